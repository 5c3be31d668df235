"""The window's dialogs: connection settings and passwords, the server's configuration, the console,
"why won't it move?", robot details, About, the command palette and the Turn / Go amount dialogs.

Each is a window of its own, transient for the main window (so typing in it never reaches the drive
keys, and ``stop_keys`` gives it Space all the same), opened by a menu action or — for Turn, Go and
the palette — by the controller after it stopped the robot. What a dialog asks of a robot goes as an
intent to the *selected* robot (``request``); a dialog that watches something on the robot (the
details' status strings, the configuration's ``configUpdated``) moves that watch along on a switch of
robot (:meth:`SelectedRobot.on_switch <rtmu.fleet.selected.SelectedRobot.on_switch>`).
Passwords typed in the settings or at a prompt are remembered here for this run.
"""

from __future__ import annotations

import concurrent.futures
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import GLib, Gtk  # noqa: E402

from ..base.i18n import _  # noqa: E402
from ..client.custom_commands import CustomCommand  # noqa: E402
from ..fleet.selected import SelectedRobot  # noqa: E402
from ..fleet.sessions import RobotSession  # noqa: E402
from ..model.observables import Phase, RobotModel  # noqa: E402
from ..settings.store import Profile  # noqa: E402
from ..values.intents import (  # noqa: E402
    AskWhy,
    Intent,
    ListServerCommands,
    MoveDistance,
    RunServerCommand,
    TurnBy,
    WatchStrings,
)
from .banners import BannerStack  # noqa: E402

if TYPE_CHECKING:  # each dialog's module is imported when it first opens (issue 28: launch ≤ 0.6 s)
    from .config_page import ConfigPage
    from .console_page import ConsolePage
    from .details import DetailsWindow
    from .settings_dialog import ConnectionDialog
    from .why_window import WhyWindow

Request = Callable[[Intent], "concurrent.futures.Future[Any]"]


class WindowDialogs:
    """See the module notes. ``profile_saved(profile, password)`` is the app's hook for settings;
    ``profile_changed`` tells the window the profile shown changed (its header follows)."""

    def __init__(
        self,
        window: Gtk.Window,
        robot: SelectedRobot,
        model: RobotModel,
        banners: BannerStack,
        *,
        request: Request,
        profiles: Mapping[str, Profile] | None = None,
        keyring_available: bool | Callable[[], bool] = False,
        profile_saved: Callable[[Profile, str | None], None] | None = None,
        profile_changed: Callable[[], None] = lambda: None,
        why_question: Callable[[], AskWhy] = AskWhy,
    ) -> None:
        self.window, self.robot, self.model, self.banners = window, robot, model, banners
        self.request = request
        self.profiles = dict(profiles or {})
        self.keyring_available = keyring_available
        """Whether passwords can be remembered: asked when the settings open (the keyring is loaded
        only then, or when a password is needed — 30 MiB and 0.1 s a start otherwise)."""
        self._profile_saved, self._profile_changed = profile_saved, profile_changed
        self._passwords: dict[str, str] = {}
        self.settings: ConnectionDialog | None = None
        """The connection settings dialog last opened."""
        self.details: DetailsWindow | None = None
        self.config_page: ConfigPage | None = None
        self.why: WhyWindow | None = None
        self.console: ConsolePage | None = None
        """The console page last opened."""
        """The "why won't it move?" window last opened."""
        self._why_question = why_question
        self._config_listener: Callable[[], None] | None = None
        robot.on_switch(self._details_follow)
        robot.on_switch(self._config_follow)
        robot.on_switch(self._why_and_console_follow)

    # -- connection settings and passwords -----------------------------------------------------
    def password_for(self, profile: Profile) -> str | None:
        """The password typed for ``profile`` in this run (None: the keyring's, or ask)."""
        return self._passwords.get(profile.name)

    def open_settings(self) -> None:
        profiles = dict(self.profiles)
        current = self.robot.session.controller.current_profile()  # the speed and view as they are now:
        profiles[current.name] = current  # Save keeps them (never the speed the profile was opened with)
        known = self.keyring_available
        from .settings_dialog import ConnectionDialog

        self.settings = ConnectionDialog(
            self.window,
            profiles,
            current,
            on_save=self._settings_saved,
            keyring_available=known() if callable(known) else known,
        )
        self.settings.present()

    def _settings_saved(self, profile: Profile, password: str | None) -> None:
        self.profiles[profile.name] = profile
        if password is not None:
            self._passwords[profile.name] = password
        if self._profile_saved is not None:
            self._profile_saved(profile, password)
        controller = self.robot.session.controller
        changed = profile != controller.current_profile()
        controller.select_profile(profile)
        self._profile_changed()
        if changed and self.model.connection.value.phase is not Phase.DISCONNECTED:
            self.banners.tell(
                "notice:saved",
                "info",
                _("Saved “{name}”: reconnect to use it").format(name=profile.name),
                timeout=4.0,
            )

    def ask_password(self, profile: Profile, answer: Callable[[str | None], None]) -> None:
        """The controller needs a password to connect: the one typed in this run, else a prompt."""
        remembered = self._passwords.get(profile.name)
        if remembered is not None:
            answer(remembered)
            return
        from .settings_dialog import PasswordPrompt

        PasswordPrompt(self.window, profile, answer).present()

    # -- the server's configuration ------------------------------------------------------------
    def show_server_config(self) -> None:
        """The server's configuration page (its own window, so typing there never drives): one at a time."""
        page = self.config_page
        if page is None or page.closed:
            offers = lambda: self.model.connection.value.offers  # noqa: E731 - the shown robot's, always
            from .config_page import ConfigPage

            page = self.config_page = ConfigPage(
                self.window,
                self.request,
                self._follow_config_updates,
                offers,
                open_console=self.show_console,
            )
        page.present()

    def _follow_config_updates(self, listener: Callable[[], None] | None) -> None:
        """The configuration page hears another client's changes on the robot shown (and only there)."""
        self._config_listener = listener
        self.robot.session.runner.on_config_updated = listener

    def _config_follow(self, old: RobotSession, new: RobotSession) -> None:
        listener = self._config_listener
        if listener is None:
            return
        old.runner.on_config_updated = None
        new.runner.on_config_updated = listener
        listener()  # the page reads the newly selected robot's configuration

    # -- the console -----------------------------------------------------------------------------
    def show_console(self, filter_text: str = "") -> None:
        """The console page (``console_page``): one at a time, its list read once it opens;
        ``filter_text`` narrows it (the configuration page points at the robot's config data)."""
        console = self.console
        if console is None or console.closed:
            from .console_page import ConsolePage

            console = self.console = ConsolePage(self.window, self.request)
        if filter_text:
            console.search.set_text(filter_text)
        console.present()

    def _why_and_console_follow(self, _old: RobotSession, _new: RobotSession) -> None:
        """A switch of robot: an open console reads the new robot's data list, an open why window asks
        the new robot (neither keeps showing the robot before)."""
        console, why = self.console, self.why
        if console is not None and not console.closed:
            console.robot_switched()
        if why is not None and not why.closed:
            why.ask()

    # -- why won't it move? ---------------------------------------------------------------------
    def show_why(self) -> None:
        """Why won't it move? (``why_window``): one at a time; opened again, it asks again."""
        why = self.why
        if why is None or why.closed:
            from .why_window import WhyWindow

            why = self.why = WhyWindow(self.window, self.request, self._why_question)
        else:
            why.ask()
        why.present()

    # -- robot details ---------------------------------------------------------------------------
    def show_details(self) -> None:
        """The details window (DataStore strings, docking, say): one at a time."""
        details = self.details
        if details is None or not details.get_visible():
            robot = self.robot
            from .details import DetailsWindow

            details = self.details = DetailsWindow(
                self.window, self.model, robot.ask, lambda on: robot.ask(WatchStrings(on))
            )
        details.present()

    def _details_follow(self, old: RobotSession, new: RobotSession) -> None:
        details = self.details
        if details is not None and details.get_visible():
            old.controller.ask(WatchStrings(False))
            new.controller.ask(WatchStrings(True))

    # -- About -----------------------------------------------------------------------------------
    def show_about(self) -> None:
        """Help ▸ About, with the debug information of the robot shown (``about``)."""
        conn = self.model.connection.value
        from .about import about_dialog

        about_dialog(self.window, conn, self.robot.session.controller.profile.name).present()

    # -- the controller's dialogs: Turn, Go, the palette -----------------------------------------
    def open_dialog(self, name: str) -> None:
        """The dialog a command asked for (the controller stopped the robot first)."""
        ask = self.robot.ask
        from .move_dialogs import go_dialog, turn_dialog
        from .palette import CommandPalette

        makers: dict[str, Callable[[], Gtk.Window]] = {
            "turn": lambda: turn_dialog(self.window, lambda degrees: ask(TurnBy(degrees))),
            "go": lambda: go_dialog(self.window, lambda mm: ask(MoveDistance(mm))),
            "commands": lambda: CommandPalette(
                self.window, lambda: self.request(ListServerCommands()), self._run_server_command
            ),
        }
        makers[name]().present()

    def _run_server_command(self, command: CustomCommand, argument: str | None) -> None:
        """From the palette: sent on the network thread; the outcome comes back as a banner."""

        def done(future: concurrent.futures.Future[bool]) -> None:
            if future.cancelled() or future.exception() is not None:
                return  # the runner already raised a Kind.COMMAND notice with the reason
            said = _("taken by the server") if future.result() else _("sent; the server did not answer")
            GLib.idle_add(self._tell_once, "server-command", f"{command.name}: {said}")

        self.request(RunServerCommand(command.name, argument, command.takes_argument)).add_done_callback(done)

    def _tell_once(self, topic: str, text: str) -> bool:
        self.banners.tell(topic, "info", text, timeout=4.0)
        return False  # an idle callback: once

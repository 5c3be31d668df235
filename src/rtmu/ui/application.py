"""The ``Gtk.Application``: settings → profile, the fleet and its first robot session, the window.

Wiring only. The application builds a :class:`rtmu.fleet.sessions.Fleet` — of one
:class:`~rtmu.fleet.sessions.RobotSession` for a one-robot profile, or of the robots a
fleet profile's roster names (``fleet.direct_roster``; at most the profile's
``connect_at_most`` connected at once), each session's network thread posting back with
``GLib.idle_add`` — ONE guardian process for the window (``rtmu.guardian.shared``,
armed for the selected robot), and a window that shows the selected session
(``fleet_bind`` adds the robot list and the other robots on the map). Every way
out — closing, quitting, Ctrl+Z, a signal — goes through the fleet, so every
robot is stopped first; then the sessions close together within one bounded wait, then
the profile's view choices (zoom, follow, sonar, speed) are saved.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import Callable
from dataclasses import replace
from types import FrameType
from typing import TYPE_CHECKING

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gio, GLib, Gtk  # noqa: E402

from ..base import dataclass_code  # noqa: E402
from ..base.heap import settle  # noqa: E402
from ..base.i18n import N_, _  # noqa: E402
from ..base.memory import give_back  # noqa: E402
from ..client.mapcache import SharedMaps  # noqa: E402
from ..client.roster import RobotEndpoint, Roster  # noqa: E402
from ..client.session import SessionConfig  # noqa: E402
from ..fleet.sessions import Fleet, RobotSession, direct_roster, robot_profile  # noqa: E402
from ..guardian.shared import SharedGuardian  # noqa: E402
from ..model.observables import NearPeople, Phase  # noqa: E402
from ..settings.secrets import KeyringSecrets  # noqa: E402
from ..settings.store import (  # noqa: E402
    DEFAULT_PORT,
    Profile,
    Settings,
    address_name,
    load_settings,
    parse_central,
    save_settings,
)
from .fleet_bind import FleetBinding  # noqa: E402
from .keys import accelerated  # noqa: E402
from .options import APP_ID, GuiOptions  # noqa: E402
from .selected_model import SelectedModel  # noqa: E402

if TYPE_CHECKING:  # the replay bar (and the MCAP reader under it) is imported by replay mode only
    from .replay_bar import ReplayBar
from .style import install_css  # noqa: E402
from .window import MainWindow  # noqa: E402

RUNNER_CLOSE_TIMEOUT = 1.5
SUSPEND_STOP_TIMEOUT = 0.5
"""How long Ctrl+Z (SIGTSTP) waits for the stop to leave the process before the process freezes anyway."""
SETTLE_AFTER_MS = 3000
"""The window's start-up objects are settled (``base.heap``) this long after it is first shown."""
SETTLE_RETRY_MS = 1000
"""How often a settling put off by a held drive looks again (``_settle_heap``)."""
GLIB_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGUSR1, signal.SIGUSR2)
"""Signals GLib's main loop can watch (``GLib.unix_signal_add``); the others are handled in Python."""
PYTHON_SIGNALS = (signal.SIGQUIT, signal.SIGALRM)
"""Signals that would kill the process by default and that GLib cannot watch: a Python handler."""
_NO_BREAK = "\u2060"  # WORD JOINER: the line may not break here (not after the hyphens of "--demo")
FIRST_RUN_WORDS = N_(
    "No robot set up yet: open the menu ☰ → Server → Connection settings (Ctrl+,) — "
    "or try the simulator: {demo}"
)
DEMO_COMMAND = f"rtmu{_NO_BREAK}\u00a0-{_NO_BREAK}-{_NO_BREAK}demo"
FIRST_RUN_HINT = FIRST_RUN_WORDS.format(demo=DEMO_COMMAND)
"""Said on the first start; the menu button is on screen in a window and in full screen alike."""


class SessionSecrets:
    """The keyring when there is one; otherwise passwords are kept in memory for this session only."""

    def __init__(self, keyring: KeyringSecrets) -> None:
        self.keyring = keyring
        self._memory: dict[str, str] = {}

    @property
    def available(self) -> bool:
        return self.keyring.available

    def get(self, profile: Profile) -> str | None:
        found = self.keyring.get(profile)
        return found if found is not None else self._memory.get(profile.keyring_user)

    def set(self, profile: Profile, password: str) -> None:
        if not self.keyring.set(profile, password):
            self._memory[profile.keyring_user] = password


class RtmuApplication(Gtk.Application):
    def __init__(self, options: GuiOptions | None = None) -> None:
        super().__init__(application_id=APP_ID, flags=Gio.ApplicationFlags.NON_UNIQUE)
        self.options = options or GuiOptions()
        self.fleet = Fleet()
        self.window: MainWindow | None = None
        self.fleet_binding: FleetBinding | None = None
        self._stand_in: RobotSession | None = None
        """What the window shows while a fleet has no robot yet (never connected, not in the fleet)."""
        self._fleet_notes: list[str] = []
        """Roster notices said before the window existed."""
        self.settings = Settings()
        self.secrets = SessionSecrets(KeyringSecrets())
        self.settings_warning: str | None = None
        self.failed = False
        """The window could not be built (the error was printed); ``run_gui`` exits non-zero."""
        self._signal_sources: list[int] = []
        self._old_handlers: dict[int, Callable[[int, FrameType | None], object] | int | None] = {}
        self._old_sigtstp: Callable[[int, FrameType | None], object] | int | None = None
        self.replay_bar: ReplayBar | None = None
        """The replay's controls (``rtmu replay``), None for a robot."""
        self.suspensions = 0
        """Times the process was suspended (Ctrl+Z) and resumed."""
        self._settle_source = 0
        """The pending settling's timer (``_settle_heap``), 0 once it ran or the window closed."""

    # -- lifecycle -----------------------------------------------------------------------------
    def do_startup(self) -> None:
        Gtk.Application.do_startup(self)
        if GLib.get_application_name() != "RTMU":
            GLib.set_application_name("RTMU")
        install_css()
        quit_action = Gio.SimpleAction.new("quit", None)
        quit_action.connect("activate", lambda _a, _p: self.quit_safely())
        self.add_action(quit_action)
        for binding in accelerated():  # F11, Ctrl+T, Ctrl+comma, Ctrl+?, Ctrl+Q: from the one key table
            self.set_accels_for_action(binding.action, list(binding.accels))
        # Ctrl+C, kill, a closed terminal (SIGHUP), Ctrl+\ (SIGQUIT), SIGUSR1/2 and SIGALRM all end the
        # window the same way: stop the robot first, then quit. Left to their default, they would kill
        # the process with the robot still driving until the server's watchdog noticed.
        # Above every other source (a central server's robots arrive as thousands of idle callbacks).
        for signum in GLIB_SIGNALS:
            self._signal_sources.append(GLib.unix_signal_add(GLib.PRIORITY_HIGH, signum, self._on_signal))
        # GLib does not watch these: a Python handler (PyGObject wakes the main loop for it).
        for signum in PYTHON_SIGNALS:
            self._old_handlers[signum] = signal.signal(signum, self._on_python_signal)
        # Ctrl+Z freezes the process, network thread included: stop the robot before that happens.
        self._old_sigtstp = signal.signal(signal.SIGTSTP, self._on_suspend)

    def _settle_heap(self) -> bool:
        """Once the window is built and shown: later full collections skip what it built (``base.heap``),
        so one does not hold every thread — the network loop's stops too — for 100 ms and more.

        Never while a drive is held: settling is itself one such pass over everything the start-up
        built, on this thread, and on a loaded machine it can outlast the lease (the likely cause of
        CI's "the drive was not renewed for 0.34 s" early in a window's life). It waits, looking
        again every :data:`SETTLE_RETRY_MS`, until the operator's keys are released."""
        window = self.window
        if window is not None and window.controller.needs_tick:
            self._settle_source = GLib.timeout_add(SETTLE_RETRY_MS, self._settle_heap)
            return False
        self._settle_source = 0
        if window is not None:  # closed meanwhile: nothing of it to settle
            dataclass_code.release()  # its classes are made: the cached compilations are done with
            settle()
            give_back()  # what the start-up freed (the table, the build's temporaries) to the system
        return False

    def do_activate(self) -> None:
        if self.window is not None:
            self.window.present()
            return
        loaded = load_settings(self.options.settings_path)
        self.settings = loaded.settings
        self.settings_warning = loaded.warning
        profile, auto_connect = self.choose_profile()
        if self.options.protocol is not None:  # --protocol: this run only, the saved profile keeps its own
            profile = replace(profile, protocol=self.options.protocol)
        # One download per map file for the whole fleet (robots of one site share their map).
        config = SessionConfig(guardian=self.options.guardian_per_robot, shared_maps=SharedMaps())
        replay = None
        if self.options.replay is not None:  # the recorder's replay is loaded for a replay only
            from .replay_mode import open_replay

            replay = open_replay(self.options.replay, self.options.replay_conn)
        roster: Roster | None = None
        mirror: SelectedModel | None = None
        if replay is not None:  # a recording: its own profile and config, not recorded again
            from ..recorder.replay import REPLAY_CONFIG
            from .replay_mode import replay_profile

            profile, auto_connect, config = replay_profile(replay.recorded.path), False, REPLAY_CONFIG
            self.options = replace(self.options, persist=False)
            session = self.fleet.open(
                post=GLib.idle_add,
                config=config,
                profile=profile,
                secrets=self.secrets,
                recording=None,
                opener=replay.open,
                clock=replay.clock.seconds,  # a replay runs on its own time
            )
        else:
            # The guardian: ONE separate process that stops the selected robot if this one is killed
            # or frozen, started now so that it is warm when the first robot is selected.
            if self.options.guardian and not self.options.guardian_per_robot:
                self.fleet.guardian = SharedGuardian()
            self.fleet.connect_at_most = self.options.connect_at_most or profile.connect_at_most
            roster = self.roster_for(profile)
            if roster is not None:
                session = self._follow(roster, profile, config)
                mirror = SelectedModel(session.state)
                auto_connect = False  # each robot connected as it was added
            else:
                session = self.fleet.open(
                    post=GLib.idle_add,
                    config=config,
                    profile=profile,
                    secrets=self.secrets,
                    recording=self.settings.recording,
                    guardian=self.fleet.guardian,
                )
        # Nothing to ask (no login): the link opens while the window is built, and the map is on its
        # way when the window first draws. What the network side learns waits in the main loop's
        # queue until the window is there to show it.
        early = auto_connect and not session.controller.profile.user  # (a replay or a roster: never auto)
        if early:
            session.controller.connect()
        try:
            window = MainWindow(
                self,
                session,
                self.fleet.operator,
                profile=session.controller.profile,
                profiles=self.settings.profiles,
                secrets=self.secrets,
                keyring_available=lambda: self.secrets.available,
                profile_saved=self.profile_saved,
                model=mirror,
            )
            if roster is not None:
                self.fleet_binding = FleetBinding(window, self.fleet)
        except Exception:
            self.failed = True
            self.close_session()
            self.quit()
            raise
        self.window = window
        window.handheld.set_muted(self.settings.alarms_muted)
        window.handheld.on_mute = self._alarms_muted
        cap = self.settings.near_people_mm_s or NearPeople().mm_s
        window.near_people.use(NearPeople(self.settings.near_people, cap))
        window.near_people.on_change = self._near_people
        window.layers.use_choices(self.settings.layers)  # the operator's drawings, remembered per server
        window.desktop.notifier.use(self.settings.notifications, on_change=self._notifications)
        # Closing the window stops every robot of the fleet, not only the one it shows.
        window.connect("close-request", lambda _w: self.fleet.stop_all() and False)
        if self.options.report_first_frame:
            window.stage.on_first_map_frame = self._report_first_frame
        if self.options.fullscreen:
            window.fullscreen()
        window.present()
        self._settle_source = GLib.timeout_add(SETTLE_AFTER_MS, self._settle_heap)
        if loaded.warning:
            window.banners.tell("notice:settings", "warning", loaded.warning, timeout=10.0)
        for note in self._fleet_notes:
            self._announce(note)
        if replay is not None:
            from .replay_mode import show_replay

            self.replay_bar = show_replay(window, session, replay)
        elif auto_connect:
            if not early:
                window.connect_now()
        elif not self.settings.profiles and not self.options.host and roster is None:
            window.banners.tell(
                "notice:hint", "info", _(FIRST_RUN_WORDS).format(demo=DEMO_COMMAND), timeout=12.0
            )

    def roster_for(self, profile: Profile) -> Roster | None:
        """Where a fleet profile's robots come from (None: a one-robot profile)."""
        if self.options.fleet:
            return direct_roster(Profile(_("demo fleet"), robots=self.options.fleet))
        if profile.central:
            host, port = parse_central(profile.central)
            password = self.secrets.get(profile) or "" if profile.user else ""
            from ..client.central import CentralRoster  # a central server's profile only

            return CentralRoster(host, port, user=profile.user, password=password, post=GLib.idle_add)
        return direct_roster(profile)

    def _follow(self, roster: Roster, profile: Profile, config: SessionConfig) -> RobotSession:
        """Build the fleet from ``roster``; the first robot is the one the window shows first."""

        def make(endpoint: RobotEndpoint) -> RobotSession:
            return RobotSession(
                self.fleet.operator,
                post=GLib.idle_add,
                config=config,
                profile=robot_profile(profile, endpoint),
                secrets=self.secrets,
                recording=self.settings.recording,
                guardian=self.fleet.guardian,
            )

        self.fleet.follow(roster, make, self._announce)
        session = self.fleet.selected.value
        if session is None:
            # A roster that announces its robots later (a central server): the window shows this
            # unconnected stand-in until the first robot arrives and is selected.
            session = RobotSession(self.fleet.operator, post=GLib.idle_add, config=config, profile=profile,
                                   secrets=self.secrets).start()  # fmt: skip
            self._stand_in = session
        return session

    def _announce(self, text: str) -> None:
        """A roster notice (a robot left, the robot list was lost): a banner, or kept until there is one."""
        if self.window is None:
            self._fleet_notes.append(text)
        else:
            self.window.banners.tell(f"fleet:{text}", "warning", text, timeout=10.0)

    def do_shutdown(self) -> None:
        self.close_session()
        Gtk.Application.do_shutdown(self)

    @property
    def session(self) -> RobotSession | None:
        """The robot session the window shows (the fleet's selection)."""
        return self.fleet.selected.value

    def close_session(self) -> None:
        """Stop every robot, close the sessions, save view choices. Idempotent (tests call it too)."""
        self.fleet.stop_all()
        window, self.window = self.window, None
        if self.fleet_binding is not None:
            self.fleet_binding.close()
            self.fleet_binding = None
        if window is not None:
            self._remember_view(window)
            window.shutdown()
        self.fleet.close(RUNNER_CLOSE_TIMEOUT)
        if self._stand_in is not None:
            self._stand_in.close(RUNNER_CLOSE_TIMEOUT)
            self._stand_in = None
        if self.options.persist and window is not None:
            self._save(background=False)
        if self._settle_source:  # a closed window settles nothing (another may live in this process)
            GLib.source_remove(self._settle_source)
            self._settle_source = 0
        for source in self._signal_sources:
            GLib.source_remove(source)
        self._signal_sources = []
        for signum, old in self._old_handlers.items():
            if old is not None:
                signal.signal(signum, old)
        self._old_handlers = {}
        if self._old_sigtstp is not None:
            signal.signal(signal.SIGTSTP, self._old_sigtstp)
            self._old_sigtstp = None

    def quit_safely(self) -> None:
        """Stop every robot, then close every window (the shutdown handler does the rest)."""
        self.fleet.stop_all()
        for w in list(self.get_windows()):
            w.close()
        self.quit()

    def _on_signal(self) -> bool:
        self.quit_safely()
        return True

    def _on_python_signal(self, _signum: int, _frame: object) -> None:
        source = GLib.idle_source_new()  # above every other source (the stubs' idle_add has no priority)
        source.set_priority(GLib.PRIORITY_HIGH)
        source.set_callback(lambda *_args: self._on_signal() and False)
        source.attach(None)

    def _on_suspend(self, _signum: int, _frame: object) -> None:
        """SIGTSTP: end any held drive (as a focus loss), make sure the stop is out, then really stop.

        A frozen process sends nothing — neither drive commands nor a stop — so the stop must
        leave before the freeze. Then the default action is restored and the signal raised again
        (the shell sees a normal job stop); once SIGCONT resumes us, ``raise_signal`` returns and
        this handler is put back. Held keys stay blocked until released: no drive resumes alone.
        """
        window = self.window
        if window is not None:
            window.end_held_drive(keep_focus=True)
        self.fleet.stop_all(wait=SUSPEND_STOP_TIMEOUT)
        signal.signal(signal.SIGTSTP, signal.SIG_DFL)
        try:
            signal.raise_signal(signal.SIGTSTP)  # the process stops here until SIGCONT
        finally:
            if self._old_sigtstp is not None:  # not closed meanwhile
                signal.signal(signal.SIGTSTP, self._on_suspend)
        self.suspensions += 1
        if self.window is not None:
            self.window.banners.tell(
                "notice:suspended",
                "warning",
                _(
                    "The window was suspended (pid {getpid}): the robot was stopped. Press a key to drive."
                ).format(getpid=os.getpid()),
                timeout=6.0,
            )

    # -- profiles ------------------------------------------------------------------------------
    def choose_profile(self) -> tuple[Profile, bool]:
        """The profile to open with and whether to connect at once."""
        o = self.options
        s = self.settings
        if o.fleet:
            return Profile(_("demo fleet"), robots=o.fleet), True
        if o.central:
            return Profile(
                _("central {central}").format(central=o.central), central=o.central, user=o.user or ""
            ), True
        if o.host:
            port = o.port or DEFAULT_PORT
            user = o.user or ""
            match = next(
                (p for p in s.profiles.values() if (p.host, p.port, p.user) == (o.host, port, user)), None
            )
            name = o.profile or (match.name if match else address_name(o.host, port, user))
            base = match or s.profiles.get(name) or Profile(name=name)
            profile = replace(base, name=name, host=o.host, port=port, user=user)
            if o.persist:
                s.put(profile)
            return profile, o.connect is not False
        if o.profile and o.profile in s.profiles:
            s.last_profile = o.profile
            return s.profiles[o.profile], o.connect is not False
        profile = s.current()
        if o.port:
            profile = replace(profile, port=o.port)
        return profile, bool(s.profiles) and o.connect is not False

    def profile_saved(self, profile: Profile, password: str | None) -> None:
        self.settings.put(profile)
        if password is not None and profile.remember_password:
            self._store_password(profile, password)
        if self._saves_asked:
            self._save(background=True)

    @property
    def _saves_asked(self) -> bool:
        """Whether what the operator saves on purpose (a profile, near people, muted alarms) is written.
        ``--demo`` writes nothing by itself (its simulator's port changes every run) but keeps what the
        operator saved; a replay writes nothing."""
        return self.options.persist or (self.options.demo and self.options.replay is None)

    def _store_password(self, profile: Profile, password: str) -> None:
        """Into the keyring off the GTK thread: D-Bus or an unlock prompt may block for seconds.

        The runner's one worker also does the lookups, so a later lookup sees this password.
        """
        secrets, session = self.secrets, self.session
        runner = session.runner if session is not None else None
        if runner is None:
            secrets.set(profile, password)
            return

        def stored(_result: None) -> None:
            pass  # SessionSecrets falls back to memory itself; nothing to tell the operator

        runner.run_blocking(lambda: secrets.set(profile, password), stored)

    def _remember_view(self, window: MainWindow) -> None:
        operator = self.fleet.operator
        view = operator.view.value
        name = window.controller.profile.name
        if name not in self.settings.profiles:
            return
        zoom = max(0.0, min(100.0, view.zoom))
        self.settings.remember_view(
            name,
            zoom=zoom,
            follow_robot=view.follow_robot,
            show_sonar=view.show_sonar,
            speed=operator.speed.value.percent,
        )

    def _near_people(self, setting: NearPeople) -> None:
        if (self.settings.near_people, self.settings.near_people_mm_s or NearPeople().mm_s) == (
            setting.on,
            setting.mm_s,
        ):
            return
        self.settings.near_people = setting.on
        self.settings.near_people_mm_s = None if setting.mm_s == NearPeople().mm_s else setting.mm_s
        if self._saves_asked:
            self._save(background=True)

    def _notifications(self, choices: dict[str, bool]) -> None:
        self.settings.notifications = dict(choices)
        if self.options.persist:
            self._save(background=True)

    def _alarms_muted(self, muted: bool) -> None:
        self.settings.alarms_muted = muted
        if self._saves_asked:
            self._save(background=True)

    def _save(self, *, background: bool) -> None:
        s = self.settings
        snapshot = Settings(
            dict(s.profiles),
            s.last_profile,
            s.recording,
            alarms_muted=s.alarms_muted,
            near_people=s.near_people,
            near_people_mm_s=s.near_people_mm_s,
            layers={server: dict(choices) for server, choices in s.layers.items()},
            notifications=dict(s.notifications),
        )
        path = self.options.settings_path

        def write() -> None:
            try:
                save_settings(snapshot, path)
            except (OSError, ValueError) as exc:
                print(_("rtmu: could not save the settings: {error}").format(error=exc), file=sys.stderr)

        if background:
            threading.Thread(target=write, name="rtmu-save-settings", daemon=True).start()
        else:
            write()

    # -- benchmark hook ------------------------------------------------------------------------
    def _report_first_frame(self, _when: float) -> None:
        print("rtmu: first map frame", flush=True)

    @property
    def connected(self) -> bool:
        session = self.session
        return session is not None and session.state.connection.value.phase is Phase.CONNECTED

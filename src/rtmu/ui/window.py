"""The main window: it composes the parts, holds them, and is the controller's View. Nothing more.

It shows the selected :class:`~rtmu.fleet.sessions.RobotSession` with the operator's choices and owns no
socket, no blocking call and no feature of its own; each lives in a part: ``bars`` (the header, STOP first
and always on screen, and the full-screen bar), ``map_page``, ``camera_page`` (and where pictures go),
``toolbar``, ``banners``, ``actions`` (every ``win.*`` action and the menu), ``keys`` (the one key table),
``stop_keys`` (Space stops from every surface), ``keyboard_nav``, ``key_reach``, ``notice_router`` (where
things are said), ``window_dialogs``, ``handheld``, ``near_people``, ``bridge_toggle``, ``why_hint`` (a
still held drive asks why), ``commissioning`` (files, scanning, map edits), ``desktop_citizen``; a new page
goes into ``stack``, a new action into ``actions``, a new dialog into ``window_dialogs``.

Its timers (``window_timers``) are the UI's heartbeat: while a drive is held they renew the drive
lease every :data:`rtmu.control.held_drive.TICK` — if this loop ever stalls, the lease lapses and
the network side stops the robot — and beat for the guardian process; at rest one slow timer
refreshes ages (stale values, picture age) once a second.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Protocol

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

from ..base.notices import Notice  # noqa: E402
from ..control.commands import CommandState  # noqa: E402
from ..control.controller import Controller  # noqa: E402
from ..control.ports import SecretStore  # noqa: E402
from ..fleet.selected import SelectedRobot  # noqa: E402
from ..fleet.sessions import RobotSession  # noqa: E402
from ..model.observables import ConnectionState, MapModel, OperatorState, Phase, RobotModel, SpeedSetting  # noqa: E402
from ..settings.store import Profile  # noqa: E402
from .actions import WindowActions  # noqa: E402
from .banners import BannerStack  # noqa: E402
from .bars import FullscreenBar, HeaderBar  # noqa: E402
from .bridge_toggle import BridgeToggle  # noqa: E402
from .camera_page import CameraPage  # noqa: E402
from .commissioning import Commissioning  # noqa: E402
from .desktop_citizen import DesktopCitizen  # noqa: E402
from .dialog_chain import close_popovers, dialogs_of  # noqa: E402
from .drive_input import DriveInput  # noqa: E402
from .goals_panel import GoalsPanel  # noqa: E402
from .handheld import Handheld  # noqa: E402
from .key_reach import KeyReach  # noqa: E402
from .keyboard_nav import KeyboardNav  # noqa: E402
from .keys_window import KeysHelp  # noqa: E402
from .map_page import MapPage  # noqa: E402
from .nav_draw import MarkerKind  # noqa: E402
from .near_people import NearPeopleSwitch  # noqa: E402
from .notes import status_line  # noqa: E402
from .notice_router import NoticeRouter, say_stop, speed_banner  # noqa: E402
from .routes_panel import RoutesPanel  # noqa: E402
from .selected_model import SelectedModel  # noqa: E402
from .split_view import SplitView  # noqa: E402
from .stop_keys import StopKeys  # noqa: E402
from .toolbar import StatusToolbar  # noqa: E402
from .why_hint import WhyContext, WhyHint  # noqa: E402
from .window_dialogs import WindowDialogs  # noqa: E402
from .window_timers import WindowTimers  # noqa: E402

if TYPE_CHECKING:
    from .details import DetailsWindow


class _Part(Protocol):
    def close(self) -> None: ...


class _View:
    """The controller's ``View`` (a separate object: ``notify`` is a GObject method on the window)."""

    def __init__(self, window: MainWindow) -> None:
        self.window = window

    def notify(self, notice: Notice) -> None:
        say_stop(notice)
        self.window.show_notice(notice)

    def commands_changed(self, states: Mapping[str, CommandState]) -> None:
        self.window.commands_changed(states)

    def ask_password(self, profile: Profile, answer: Callable[[str | None], None]) -> None:
        self.window.dialogs.ask_password(profile, answer)

    def open_dialog(self, name: str) -> None:
        self.window.dialogs.open_dialog(name)

    def driving(self) -> None:
        self.window.timers.drive_started()


class MainWindow(Gtk.ApplicationWindow):
    """See the module notes. ``profile_saved(profile, password)`` is the app's hook for settings."""

    def __init__(
        self,
        app: Gtk.Application,
        session: RobotSession,
        operator: OperatorState,
        *,
        profile: Profile,
        profiles: Mapping[str, Profile] | None = None,
        secrets: SecretStore | None = None,
        keyring_available: bool | Callable[[], bool] = False,
        profile_saved: Callable[[Profile, str | None], None] | None = None,
        clock: Callable[[], float] = time.monotonic,
        model: RobotModel | None = None,
    ) -> None:
        super().__init__(application=app, title="RTMU")
        self.set_default_size(800, 480)
        self.set_size_request(360, 320)  # 360: a portrait phone (ui.layout)
        self.model = model = model or session.state  # a fleet's: the selected robot's (``selected_model``)
        self.operator, self.clock = operator, clock
        self.robot = SelectedRobot(session)
        """The robot the operator commands: every part's intents go to the selected one."""
        status_age = lambda: self.session.runner.status_age()  # noqa: E731 - the shown robot's, always
        self.banners = BannerStack()
        self.notices = NoticeRouter(
            self.banners, connection=lambda: self.model.connection.value,
            speed_percent=lambda: self.operator.speed.value.percent, picture=lambda: self.camera,
        )  # fmt: skip
        self.toolbar = StatusToolbar(model, operator, clock=clock, status_age=status_age)
        self.actions = WindowActions(self)  # the menu now, the actions once the parts they run exist
        self.menu_model, self.robot_menu = self.actions.menu_model, self.actions.robot_menu
        self.view_menu, self.app_menu = self.actions.view_menu, self.actions.app_menu
        self.map_page = m = MapPage(
            model, operator, self.robot, clock=clock, status_age=status_age,
            show_camera=self.show_camera, show_map=self.show_map, hide_inset=self.actions.hide_inset,
        )  # fmt: skip
        self.stage, self.dpad, self.inset, self.motion = m.stage, m.dpad, m.inset, m.motion
        self.picker, self.pose_bar, self.popup_stack = m.picker, m.pose_bar, m.popup_stack
        self.layers, self.map_note, self.follow_button = m.layers, m.note, m.follow_button
        self.drive = DriveInput(self.robot, m, activate=self.actions.activate, pick_key=self._pick_key)
        self.keys = self.drive.router  # before the stop keys' controller, which GTK runs first
        self.add_controller(self.keys.controller)
        why = WhyContext(self.robot, model, self.keys)  # what the window knows of a drive, for "why?"
        self.why_hint = WhyHint(why, self.banners, clock)  # a held drive and no motion for 1 s: ask why
        self.stack = Gtk.Stack(transition_type=Gtk.StackTransitionType.NONE)
        """The window's pages by name: ``map`` (the map page, split with the live picture), ``camera``."""
        self.split = SplitView(m)  # the map page, and the live picture beside it while split
        self.camera_page = c = CameraPage(
            model, self.robot, self.banners, stack=self.stack, inset=self.inset, split=self.split,
            command_state=self.command_state, page_changed=self._page_changed, clock=clock,
        )  # fmt: skip
        self.camera, self.ptz, self.live = c.view, c.ptz, c.live
        m.dpad_place.follow_pages(self.stack, c.view.overlay, "camera")  # the D-pad on the camera page too
        self.decoder, self.camera_button = c.decoder, c.button
        self.set_titlebar(self._header())
        self.set_child(self._body())
        self.foxglove = BridgeToggle(session, self.show_notice)  # View ▸ Foxglove bridge: publishing only
        self.robot.on_switch(self.foxglove.follow_selection)
        self.request = self.robot.request
        """An intent to the selected robot, its answer as a Future (``SelectedRobot.request``)."""
        self.dialogs = WindowDialogs(
            self, self.robot, model, self.banners, request=self.request, profiles=profiles,
            keyring_available=keyring_available, profile_saved=profile_saved,
            profile_changed=lambda: self._update_header(self.model.connection.value),
            why_question=why.question,
        )  # fmt: skip
        self.commissioning = Commissioning(  # the robot's files, scanning, map edits (bar under the toolbar)
            self, self.robot, model, column=self.column, after=self.toolbar_revealer, clock=clock,
            stage=self.stage, banners=self.banners,
        )  # fmt: skip
        if secrets is not None:
            self.controller.secrets = secrets
        # The slow tick now; the lease renewal and the guardian's beat once the controller says a
        # drive began (``View.driving``), so before the controller can say it.
        self.timers = WindowTimers(self)
        self.robot_view = _View(self)
        session.attach_view(self.robot_view)
        self.controller.select_profile(profile)
        self.operator.speed.set(SpeedSetting.nearest(profile.speed))
        self.actions.install()
        self.inset_action = self.actions.inset_action
        self.keys_help = KeysHelp(self)
        self._unobserve = [
            model.connection.observe(self._on_connection),
            operator.speed.observe(lambda _old, new: self.notices.apply(speed_banner(new.percent))),
            model.map.observe(self._on_map),
        ]
        self.connect("notify::is-active", self._on_active)
        self.connect("close-request", self._on_close_request)
        self.handheld = Handheld(self)  # gamepad, alarms, phone layout (after the focus handler above)
        self.commands_changed(self.controller.command_states())
        self._on_connection(ConnectionState(), model.connection.value)
        self._on_map(MapModel(), model.map.value)
        # Space stops from every surface (dialogs, menus, popovers); keys are never lost silently.
        self.stop_keys = StopKeys(self, self.stop_now, on_popover=self.drive.popover_took_keys)
        self.key_reach = KeyReach(self)
        self.keyboard = KeyboardNav(self)  # Tab, F10, Ctrl+G, Alt+1…9, a pick mode's keys
        self.near_people = NearPeopleSwitch(self)  # View ▸ Near people: the speed cap
        self.desktop = DesktopCitizen(
            self, model, self.motion, self.view_menu
        )  # screen kept on, notifications

    @property
    def session(self) -> RobotSession:
        """The robot session shown (the fleet's selection)."""
        return self.robot.session

    @property
    def controller(self) -> Controller:
        return self.robot.session.controller

    @property
    def details(self) -> DetailsWindow | None:
        """The robot details window last opened (``window_dialogs``)."""
        return self.dialogs.details

    # -- layout ------------------------------------------------------------------------------
    def _header(self) -> HeaderBar:
        self.routes_panel = RoutesPanel(self.model, self.robot.ask)  # only when the server lists getRoutes
        m = self.map_page  # the Go to panel shows only when the server navigates (goals, points, dock)
        run = self.actions.run_command
        self.goals_panel = GoalsPanel(self.model, goto=m.goto_goal, run=run, pick=m.start_pick)
        end = (self.camera_button, self.routes_panel, self.goals_panel)
        self.header = h = HeaderBar(
            on_stop=self.stop_now, on_connect=self.toggle_connection, menu=self.menu_model, end=end
        )
        self.stop_button, self.connect_button, self.menu_button = (
            h.stop_button,
            h.connect_button,
            h.menu_button,
        )
        self.title_label, self.subtitle_label = h.title_label, h.subtitle_label
        return h

    def _body(self) -> Gtk.Box:
        """Bars above (full screen's, the toolbar), then the pages with the banners over them."""
        slide = Gtk.RevealerTransitionType.SLIDE_DOWN
        self.toolbar_revealer = Gtk.Revealer(child=self.toolbar, reveal_child=True, transition_type=slide)
        self.toolbar_revealer.set_transition_duration(120)
        self.stack.add_named(self.split, "map")
        self.stack.add_named(self.camera, "camera")
        self.stack.set_visible_child_name("map")
        outer = Gtk.Overlay(hexpand=True, vexpand=True)
        outer.set_child(self.stack)
        outer.add_overlay(self.banners)
        # Full screen hides the header bar: this bar keeps STOP, Connect, the menu and a way out.
        self.fullscreen_bar = FullscreenBar(
            on_stop=self.stop_now, on_connect=self.toggle_connection,
            on_leave=self.leave_fullscreen, menu=self.menu_model,
        )  # fmt: skip
        self.column = Gtk.Box(orientation=Gtk.Orientation.VERTICAL)
        """The window's column (bars above, the pages); a replay appends its controls."""
        self.column.append(self.fullscreen_bar)
        self.column.append(self.toolbar_revealer)
        self.body = Gtk.Box(vexpand=True)  # the pages; a fleet's robot list goes beside or under them
        self.body.append(outer)
        self.column.append(self.body)
        return self.column

    # -- the controller's View and the selection -------------------------------------------------
    def show_notice(self, notice: Notice) -> None:
        """Show a controller/network message where its kind belongs (``notice_router``)."""
        self.notices.show(notice)

    def commands_changed(self, states: Mapping[str, CommandState]) -> None:
        """Command states → the parts that show them, then the actions (and the menu's greyed rows)."""
        self.goals_panel.commands_changed(states)
        self.camera_page.commands_changed(dict(states))
        self.map_page.commands_changed(states)
        self.actions.commands_changed(states)

    def command_state(self, name: str) -> CommandState:
        return self.actions.command_state(name)

    def ask_password(self, profile: Profile, answer: Callable[[str | None], None]) -> None:
        self.dialogs.ask_password(profile, answer)

    def open_dialog(self, name: str) -> None:
        """The dialog a command asked for (the controller stopped the robot first)."""
        self.dialogs.open_dialog(name)

    def show_session(self, session: RobotSession) -> None:
        """Show another robot of the fleet (which has already stopped the one shown before).

        Keys held now stay held in the key router, so their auto-repeat is swallowed: the new
        robot moves only on a fresh press. A finger on the D-pad is let go of.
        """
        self.map_page.let_go()
        self.robot.show(session)  # every part's intents now go to this robot; what they hold moves
        self.handheld.show_controller(self.controller)  # the pad follows the selection, never carries over
        session.attach_view(self.robot_view)
        if isinstance(self.model, SelectedModel):
            self.model.show(session.state)
        self.camera_page.robot_shown()
        self.commands_changed(self.controller.command_states())
        self._update_header(self.model.connection.value)

    # -- driving and stopping (``drive_input``) -----------------------------------------------------
    def stop_now(self) -> None:
        """The on-screen STOP: the same as Space, and sent whatever the link looks like."""
        self.drive.stop()

    def end_held_drive(self, *, keep_focus: bool = False) -> None:
        """As on a focus loss (``keep_focus``: the window keeps the keyboard, the process is suspended)."""
        self.drive.end_held_drive(still_active=keep_focus and self.is_active())

    def _on_active(self, *_a: object) -> None:
        self.drive.focus_changed(self.is_active())

    def _pick_key(self, name: str) -> bool:
        return self.keyboard.pick_key(name)

    # -- pages, connection, full screen ------------------------------------------------------------
    def show_camera(self, request: bool = False) -> None:
        self.camera_page.show_camera(request)

    def show_map(self) -> None:
        self.camera_page.show_map()

    def _page_changed(self) -> None:
        self.commands_changed({"request_image": self.command_state("request_image")})

    def start_pick(self, kind: MarkerKind) -> None:
        """Go to a point / set robot position (``map_page``)."""
        self.map_page.start_pick(kind)

    def show_details(self) -> None:
        self.dialogs.show_details()

    def leave_fullscreen(self) -> None:
        """The full-screen bar's way out (as F11)."""
        self.actions.leave_fullscreen()

    def toggle_connection(self) -> None:
        if self.model.connection.value.phase in (Phase.DISCONNECTED, Phase.FAILED):
            self.connect_now()
        else:
            self.controller.disconnect()

    def connect_now(self) -> None:
        self.controller.connect(password=self.dialogs.password_for(self.controller.profile))

    def _on_connection(self, old: ConnectionState, new: ConnectionState) -> None:
        if not self.session.closed:  # a closed robot's late news (the fleet said why it went): no banner
            self.notices.connection_changed(old, new, self.model.navigation.value)
        self.camera_page.connection_changed(old, new)
        # Held keys stay held in the key router (their auto-repeat is swallowed); the controller
        # has blocked them, so only a fresh press drives after the link comes back.
        self._update_header(new)
        self.map_page.update_note(new, self.model.map.value)

    def _on_map(self, _old: MapModel, _new: MapModel) -> None:
        self.map_page.update_note(self.model.connection.value, self.model.map.value)
        self._update_header(self.model.connection.value)

    def _update_header(self, conn: ConnectionState) -> None:
        connected_ish = conn.phase in (Phase.CONNECTED, Phase.CONNECTING, Phase.RECONNECTING)
        status = status_line(conn, self.controller.profile, self.model.map.value.name)
        for bar in (self.header, self.fullscreen_bar):
            bar.show_status(connected_ish, status)
        self.actions.enable("connect", not connected_ish)

    # -- timers, closing ---------------------------------------------------------------------------
    def _on_close_request(self, _w: Gtk.Window) -> bool:
        """Closing while driving stops the robot first; then the app shuts the network down."""
        self.controller.stop()
        self.shutdown()
        return False

    def shutdown(self) -> None:
        """Stop timers and workers (idempotent)."""
        self.timers.close()
        for remove in self._unobserve:
            remove()
        self._unobserve = []
        parts: tuple[_Part, ...] = (self.handheld, self.stop_keys, self.key_reach, self.near_people)
        for part in (*parts, self.desktop, self.map_page, self.toolbar, self.routes_panel, self.goals_panel):
            part.close()
        for part in (self.camera_page, self.foxglove, self.actions, self.commissioning):
            part.close()
        for dialog in dialogs_of(self):  # not left on screen for GTK to find when it disposes us
            close_popovers(dialog)
            dialog.destroy()
        close_popovers(self)

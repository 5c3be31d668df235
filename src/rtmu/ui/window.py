"""The main window: header bar, status toolbar, map ⇄ camera stack, banners, D-pad; the controller's View.

The window shows one :class:`rtmu.fleet.sessions.RobotSession` (its state, its
controller) with the operator's choices (:class:`rtmu.model.observables.OperatorState`); it
wires widgets to them and owns nothing else: no socket, no packet, no blocking
call, no network thread. A red STOP is always on screen:
first in the header bar, and in the slim bar that replaces the header in full
screen (``bars``). Its two timers are the UI's
heartbeat: every :data:`rtmu.control.controller.TICK` it renews the drive lease
(``controller.tick``) — if this loop ever stalls, the lease lapses and the
network side stops the robot — and a slower one refreshes ages (stale values,
picture age).

Banners have topics (see ``banners``): the connection's life (connecting,
connected, failed, lost → reconnecting (n)) is drawn from the model into ONE
``link`` banner updated in place; notices (:class:`rtmu.base.notices.Notice`) are
routed by their kind — connection notices fold into that banner, speed into the
speed banner, camera into the camera page — never by the words in their text; a
deliberate disconnect shows nothing.
"""

from __future__ import annotations

import concurrent.futures
import time
from collections.abc import Callable, Mapping
from typing import Any

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
gi.require_version("Gdk", "4.0")
from gi.repository import GLib, Gtk, Pango  # noqa: E402

from ..base.notices import Notice  # noqa: E402
from ..client.errors import ClientError  # noqa: E402
from ..control.commands import CommandState  # noqa: E402
from ..control.controller import TICK, SecretStore  # noqa: E402
from ..fleet.selected import SelectedRobot  # noqa: E402
from ..fleet.sessions import RobotSession  # noqa: E402
from ..guardian.handle import BEAT_PERIOD as GUARDIAN_BEAT  # noqa: E402
from ..model.observables import (  # noqa: E402
    SPEED_MAX,
    SPEED_MIN,
    ConnectionState,
    MapModel,
    OperatorState,
    Phase,
    RobotModel,
    SpeedSetting,
)
from ..settings.store import Profile  # noqa: E402
from ..values.intents import (  # noqa: E402
    Intent,
)
from .actions import WindowActions  # noqa: E402
from .banners import BannerStack  # noqa: E402
from .bars import FullscreenBar, connect_button, menu_button, show_connection, stop_button  # noqa: E402
from .bridge_toggle import BridgeToggle  # noqa: E402
from .camera_page import CameraPage  # noqa: E402
from .details import DetailsWindow  # noqa: E402
from .goals_panel import GoalsPanel  # noqa: E402
from .handheld import Handheld  # noqa: E402
from .key_reach import KeyReach  # noqa: E402
from .keyboard_nav import KeyboardNav  # noqa: E402
from .keys import KeyRouter  # noqa: E402
from .map_page import MapPage  # noqa: E402
from .nav_draw import MarkerKind  # noqa: E402
from .near_people import NearPeopleSwitch  # noqa: E402
from .notice_router import NoticeRouter, speed_banner  # noqa: E402
from .routes_panel import RoutesPanel  # noqa: E402
from .selected_model import SelectedModel  # noqa: E402
from .shortcuts import build_shortcuts_window  # noqa: E402
from .split_view import SplitView  # noqa: E402
from .stop_keys import StopKeys  # noqa: E402
from .toolbar import StatusToolbar  # noqa: E402
from .window_dialogs import WindowDialogs  # noqa: E402

REFRESH_EVERY = 3
"""Ticks between refreshes of ages (toolbar, picture): 0.3 s."""
LOOP_LAG_WARN = 0.5
"""Seconds without a network-loop heartbeat after which the window warns that drive commands (and
stops) are not going out; the warning goes once the lag is under half of this again."""


class _View:
    """The controller's ``View`` (a separate object: ``notify`` is a GObject method on the window)."""

    def __init__(self, window: MainWindow) -> None:
        self.window = window

    def notify(self, notice: Notice) -> None:
        self.window.show_notice(notice)

    def commands_changed(self, states: Mapping[str, CommandState]) -> None:
        self.window.commands_changed(states)

    def ask_password(self, profile: Profile, answer: Callable[[str | None], None]) -> None:
        self.window.ask_password(profile, answer)

    def open_dialog(self, name: str) -> None:
        self.window.open_dialog(name)


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
        keyring_available: bool = False,
        profile_saved: Callable[[Profile, str | None], None] | None = None,
        clock: Callable[[], float] = time.monotonic,
        model: RobotModel | None = None,
    ) -> None:
        super().__init__(application=app, title="RTMU")
        self.set_default_size(800, 480)
        self.set_size_request(360, 320)  # 360: a portrait phone (ui.layout)
        self.session = session
        self.model = model = model or session.state  # a fleet's: the selected robot's (``selected_model``)
        self.operator = operator
        self.clock = clock
        self.ticks = 0
        """Counts timer ticks: proof for tests that the main loop is alive."""

        link = session.runner
        self._link = link
        self.robot = SelectedRobot(session)
        """The robot the operator commands: every widget's intents go to the selected one."""
        status_age = lambda: self._link.status_age()  # noqa: E731 - the shown robot's, also after a switch
        self.banners = BannerStack()
        self.notices = NoticeRouter(
            self.banners,
            connection=lambda: self.model.connection.value,
            speed_percent=lambda: self.operator.speed.value.percent,
            picture=lambda: self.camera,
        )
        self.toolbar = StatusToolbar(model, operator, clock=clock, status_age=status_age)
        self.actions = WindowActions(self)  # the menu now, the actions once the parts they run exist
        self.menu_model = self.actions.menu_model
        self.robot_menu, self.view_menu = self.actions.robot_menu, self.actions.view_menu
        self.app_menu = self.actions.app_menu
        self.map_page = MapPage(
            model, operator, self.robot, clock=clock, status_age=status_age,
            show_camera=self.show_camera, show_map=self.show_map, hide_inset=self.actions.hide_inset,
        )  # fmt: skip
        page = self.map_page
        self.stage, self.dpad, self.inset, self.motion = page.stage, page.dpad, page.inset, page.motion
        self.picker, self.pose_bar, self.popup_stack = page.picker, page.pose_bar, page.popup_stack
        self.layers, self.map_note, self.follow_button = page.layers, page.note, page.follow_button
        self.keys = KeyRouter(hold=self._hold, release=self._release, activate=self.actions.activate)
        self.add_controller(self.keys.controller)

        self._build()
        self.foxglove = BridgeToggle(session, self.show_notice)  # View ▸ Foxglove bridge: publishing only
        self.robot.on_switch(self.foxglove.follow_selection)
        self.dialogs = WindowDialogs(
            self, self.robot, model, self.banners, request=self.request, profiles=profiles,
            keyring_available=keyring_available, profile_saved=profile_saved,
            profile_changed=lambda: self._update_header(self.model.connection.value),
        )  # fmt: skip
        self.controller = session.controller
        if secrets is not None:
            self.controller.secrets = secrets
        self.robot_view = _View(self)
        session.attach_view(self.robot_view)
        self.controller.select_profile(profile)
        self._set_speed_from_profile(profile)
        self.actions.install()
        self.inset_action = self.actions.inset_action
        self.set_help_overlay(build_shortcuts_window())

        self._unobserve = [
            model.connection.observe(self._on_connection),
            operator.speed.observe(self._on_speed),
            model.map.observe(self._on_map),
        ]
        self.connect("notify::is-active", self._on_active)
        self.connect("close-request", self._on_close_request)
        self._tick_source = GLib.timeout_add(int(TICK * 1000), self._tick)
        self.handheld = Handheld(self)  # gamepad, alarms, phone layout (after the focus handler above)
        # The UI thread's heartbeat to the guardian process (rtmu.guardian): it stops the robot
        # if these stop while driving because this process was killed or frozen.
        self._beat_source = GLib.timeout_add(int(GUARDIAN_BEAT * 1000), self._beat)
        self.commands_changed(self.controller.command_states())
        self._on_connection(ConnectionState(), model.connection.value)
        self._on_map(MapModel(), model.map.value)
        # Space stops from every surface (dialogs, menus, popovers); keys are never lost silently.
        self.stop_keys = StopKeys(self, self.stop_now, on_popover=self._popover_took_keys)
        self.key_reach = KeyReach(self)
        self.keyboard = KeyboardNav(self)  # Tab, F10, Ctrl+G, Alt+1…9, a pick mode's keys
        self.near_people = NearPeopleSwitch(self)  # View ▸ Near people: the speed cap

    # -- layout ------------------------------------------------------------------------------
    def _build(self) -> None:
        self.stack = Gtk.Stack(transition_type=Gtk.StackTransitionType.NONE)
        self.split = SplitView(self.map_page)  # the map page, and the live picture beside it while split
        self.camera_page = CameraPage(
            self.model, self.robot, self.banners, stack=self.stack, inset=self.inset, split=self.split,
            command_state=self.command_state, page_changed=self._camera_page_changed, clock=self.clock,
        )  # fmt: skip
        page = self.camera_page
        self.camera, self.ptz, self.live = page.view, page.ptz, page.live
        self.decoder, self.camera_button = page.decoder, page.button
        header = Gtk.HeaderBar()
        # Safety: STOP is always on screen, first in the bar and the only red button in it.
        self.stop_button = stop_button(self.stop_now)
        header.pack_start(self.stop_button)
        self.connect_button = connect_button(self.toggle_connection)
        header.pack_start(self.connect_button)
        title_box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, valign=Gtk.Align.CENTER)
        title_box.add_css_class("title-box")
        self.title_label = Gtk.Label(label="RTMU")
        self.title_label.add_css_class("title")
        self.title_label.set_ellipsize(Pango.EllipsizeMode.END)  # a 560 px window keeps its buttons
        self.subtitle_label = Gtk.Label(label="")
        self.subtitle_label.add_css_class("subtitle")
        self.subtitle_label.set_ellipsize(Pango.EllipsizeMode.END)
        self.subtitle_label.set_max_width_chars(48)
        title_box.append(self.title_label)
        title_box.append(self.subtitle_label)
        header.set_title_widget(title_box)
        self.menu_button = menu_button(self.menu_model)
        header.pack_end(self.menu_button)
        header.pack_end(self.camera_button)
        self.routes_panel = RoutesPanel(self.model, self.robot.ask)  # only when the server lists getRoutes
        header.pack_end(self.routes_panel)
        # The Go to panel shows only when the server navigates (goals, points, dock).
        goto, pick = self.map_page.goto_goal, self.map_page.start_pick
        self.goals_panel = GoalsPanel(self.model, goto=goto, run=self.actions.run_command, pick=pick)
        header.pack_end(self.goals_panel)
        self.set_titlebar(header)

        self.toolbar_revealer = Gtk.Revealer(transition_type=Gtk.RevealerTransitionType.SLIDE_DOWN)
        self.toolbar_revealer.set_transition_duration(120)
        self.toolbar_revealer.set_child(self.toolbar)
        self.toolbar_revealer.set_reveal_child(True)

        self.stack.add_named(self.split, "map")
        self.stack.add_named(self.camera, "camera")
        self.stack.set_visible_child_name("map")
        outer = Gtk.Overlay()
        outer.set_child(self.stack)
        outer.add_overlay(self.banners)

        # Full screen hides the header bar: this bar keeps STOP, Connect, the menu and a way out.
        self.fullscreen_bar = FullscreenBar(
            on_stop=self.stop_now,
            on_connect=self.toggle_connection,
            on_leave=self.leave_fullscreen,
            menu=self.menu_model,
        )
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL)
        box.append(self.fullscreen_bar)
        box.append(self.toolbar_revealer)
        self.body = Gtk.Box()  # the map and camera stack; a fleet's robot list goes beside or under it
        self.body.append(outer)
        outer.set_hexpand(True)
        box.append(self.body)
        self.body.set_vexpand(True)
        outer.set_vexpand(True)
        self.column = box
        """The window's column (bars above, the map/camera body); a replay appends its controls."""
        self.set_child(box)

    # -- the controller's View -----------------------------------------------------------------
    def show_notice(self, notice: Notice) -> None:
        """Show a controller/network message where its kind belongs (``notice_router``)."""
        self.notices.show(notice)

    def commands_changed(self, states: Mapping[str, CommandState]) -> None:
        """Command states → the parts that show them, then the actions (and the menu's greyed rows)."""
        self.goals_panel.commands_changed(states)
        self.camera_page.commands_changed(dict(states))
        self.map_page.commands_changed(states)
        self.actions.commands_changed(states)

    def ask_password(self, profile: Profile, answer: Callable[[str | None], None]) -> None:
        self.dialogs.ask_password(profile, answer)

    def command_state(self, name: str) -> CommandState:
        return self.actions.command_state(name)

    def show_session(self, session: RobotSession) -> None:
        """Show another robot of the fleet (which has already stopped the one shown before).

        Keys held now stay held in the key router, so their auto-repeat is swallowed: the new
        robot moves only on a fresh press. A finger on the D-pad is let go of.
        """
        self.map_page.let_go()
        self.session, self.controller, self._link = session, session.controller, session.runner
        self.robot.show(session)  # every widget's intents now go to this robot; what they hold moves
        self.handheld.show_controller(self.controller)  # the pad follows the selection, never carries over
        session.attach_view(self.robot_view)
        if isinstance(self.model, SelectedModel):
            self.model.show(session.state)
        self.camera_page.robot_shown()
        self.commands_changed(self.controller.command_states())
        self._update_header(self.model.connection.value)

    # -- intents -------------------------------------------------------------------------------
    def _hold(self, name: str) -> None:
        # On the camera page too: the picture shows its age, and a fresh press is the operator's intent.
        if not self.keyboard.pick_key(name):  # a pick mode's arrows move its point instead
            self.controller.run(name)

    def _popover_took_keys(self) -> None:
        """A menu or popover holds the keyboard now: held keys can no longer be seen let go."""
        self.controller.look("the menu", keys_leave=True)
        self.keys.release_all()
        self.dpad.release_all()

    def _release(self, name: str) -> None:
        self.controller.release_command(name)

    def _beat(self) -> bool:
        """The GTK thread's heartbeat to the guardian; True keeps the timer."""
        self._link.ui_heartbeat()
        return True

    def open_dialog(self, name: str) -> None:
        """The dialog a command asked for (the controller stopped the robot first)."""
        self.dialogs.open_dialog(name)

    def stop_now(self) -> None:
        """The on-screen STOP: the same as Space, and sent whatever the link looks like.

        Keys still held stay blocked by the controller until they are let go (as after Space), so
        their auto-repeat cannot start the robot again; a finger on the D-pad is let go of here.
        """
        self.controller.stop()
        self.map_page.let_go()

    def request(self, intent: Intent) -> concurrent.futures.Future[Any]:
        """:meth:`SelectedRobot.ask` for a widget that waits for the answer: a refusal (said already)
        comes back as a failed Future, so the widget's own waiting ends too."""
        future = self.robot.ask(intent)
        if isinstance(future, concurrent.futures.Future):
            return future
        refused: concurrent.futures.Future[Any] = concurrent.futures.Future()
        refused.set_exception(ClientError(f"{intent.label}: refused"))
        return refused

    def start_pick(self, kind: MarkerKind) -> None:
        """Go to a point / set robot position (``map_page``)."""
        self.map_page.start_pick(kind)

    def toggle_connection(self) -> None:
        phase = self.model.connection.value.phase
        if phase in (Phase.DISCONNECTED, Phase.FAILED):
            self.connect_now()
        else:
            self.controller.disconnect()

    def connect_now(self) -> None:
        profile = self.controller.profile
        self.controller.connect(password=self.dialogs.password_for(profile))

    def _camera_page_changed(self) -> None:
        self.commands_changed({"request_image": self.command_state("request_image")})

    def show_camera(self, request: bool = False) -> None:
        self.camera_page.show_camera(request)

    def show_map(self) -> None:
        self.camera_page.show_map()

    # -- model reactions ---------------------------------------------------------------------
    def _on_connection(self, old: ConnectionState, new: ConnectionState) -> None:
        if not self.session.closed:  # a closed robot's late news (the fleet said why it went): no banner
            self.notices.connection_changed(old, new, self.model.navigation.value)
        self.camera_page.connection_changed(old, new)
        # Held keys stay held in the key router (their auto-repeat is swallowed); the controller
        # has blocked them, so only a fresh press drives after the link comes back.
        self._update_header(new)
        self.map_page.update_note(new, self.model.map.value)

    def _update_header(self, conn: ConnectionState) -> None:
        phase = conn.phase
        connected_ish = phase in (Phase.CONNECTED, Phase.CONNECTING, Phase.RECONNECTING)
        for button in (self.connect_button, self.fullscreen_bar.connect_button):
            show_connection(button, connected_ish)
        self.actions.enable("connect", not connected_ish)
        profile = self.controller.profile
        where = f"{conn.host}:{conn.port}" if conn.host else f"{profile.host}:{profile.port}"
        state = {
            Phase.DISCONNECTED: "not connected",
            Phase.CONNECTING: "connecting…",
            Phase.CONNECTED: "connected",
            Phase.RECONNECTING: f"reconnecting ({conn.error})" if conn.error else "reconnecting",
            Phase.FAILED: f"failed: {conn.error}" if conn.error else "failed",
        }[phase]
        name = self.model.map.value.name.replace("\\", "/").rsplit("/", 1)[-1]
        parts = [profile.name, state] if where in profile.name else [profile.name, where, state]
        parts += [name] if name and phase is Phase.CONNECTED else []
        self.subtitle_label.set_text(" · ".join(parts))
        self.fullscreen_bar.status_label.set_text(" · ".join(parts))

    def _on_map(self, _old: MapModel, _new: MapModel) -> None:
        self.map_page.update_note(self.model.connection.value, self.model.map.value)
        self._update_header(self.model.connection.value)

    def _on_speed(self, _old: SpeedSetting, new: SpeedSetting) -> None:
        self.notices.apply(speed_banner(new.percent))

    # -- toggles -------------------------------------------------------------------------------
    def leave_fullscreen(self) -> None:
        """The full-screen bar's way out (as F11)."""
        self.actions.leave_fullscreen()

    def _set_speed_from_profile(self, profile: Profile) -> None:
        pct = max(SPEED_MIN, min(SPEED_MAX, profile.speed // 10 * 10))
        self.operator.speed.set(SpeedSetting(pct))

    # -- dialogs -------------------------------------------------------------------------------
    def show_details(self) -> None:
        self.dialogs.show_details()

    @property
    def details(self) -> DetailsWindow | None:
        """The robot details window last opened (``window_dialogs``)."""
        return self.dialogs.details

    # -- focus, timers, closing ----------------------------------------------------------------
    def _on_active(self, *_a: object) -> None:
        if self.is_active():
            self.controller.focus_gained()  # key releases from now on are real ones
        else:
            self.end_held_drive()

    def end_held_drive(self, *, keep_focus: bool = False) -> None:
        """Stop, and forget held keys and fingers as on a focus loss: they stay blocked until released.

        ``keep_focus``: the window still has the keyboard (the process is being suspended), so a
        release seen afterwards is a real one and unblocks its key.
        """
        self.controller.focus_lost()
        self.keys.release_all()
        self.dpad.release_all()
        if keep_focus and self.is_active():
            self.controller.focus_gained()

    def _tick(self) -> bool:
        self.ticks += 1
        self.controller.tick()
        slow = self.ticks % REFRESH_EVERY == 0
        self.map_page.refresh(slow)
        if slow:
            self.toolbar.refresh()
            self.camera_page.tick()
            self._check_loop_lag()
        return True

    def _check_loop_lag(self) -> None:
        """Warn while the network thread is stalled: then even a stop cannot leave this process."""
        loop_lag = getattr(self.controller.link, "loop_lag", None)
        lag = loop_lag() if callable(loop_lag) else None
        connected = self.model.connection.value.phase is Phase.CONNECTED
        if connected and lag is not None and lag > LOOP_LAG_WARN:
            self.banners.tell(
                "loop",
                "error",
                f"The network thread has not run for {lag:.1f} s: drive commands and stops are not going "
                "out; the robot may keep moving until the server's watchdog stops it",
                timeout=None,
            )
        elif "loop" in self.banners.topics() and (not connected or lag is None or lag < LOOP_LAG_WARN / 2):
            self.banners.dismiss("loop")

    def _on_close_request(self, _w: Gtk.Window) -> bool:
        """Closing while driving stops the robot first; then the app shuts the network down."""
        self.controller.stop()
        self.shutdown()
        return False

    def shutdown(self) -> None:
        """Stop timers and workers (idempotent)."""
        if self._tick_source:
            GLib.source_remove(self._tick_source)
            self._tick_source = 0
        if self._beat_source:
            GLib.source_remove(self._beat_source)
            self._beat_source = 0
        for remove in self._unobserve:
            remove()
        self._unobserve = []
        self.handheld.close()
        self.stop_keys.close()
        self.key_reach.close()
        self.near_people.close()
        self.map_page.close()
        self.toolbar.close()
        self.routes_panel.close()
        self.goals_panel.close()
        self.camera_page.close()
        self.foxglove.close()
        self.actions.close()

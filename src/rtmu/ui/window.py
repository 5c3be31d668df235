"""The main window: header bar, status toolbar, map ⇄ camera stack, banners, D-pad; the controller's View.

The window shows one :class:`rtmu.fleet.RobotSession` (its state, its
controller) with the operator's choices (:class:`rtmu.model.OperatorState`); it
wires widgets to them and owns nothing else: no socket, no packet, no blocking
call, no network thread. A red STOP is always on screen:
first in the header bar, and in the slim bar that replaces the header in full
screen (``bars``). Its two timers are the UI's
heartbeat: every :data:`rtmu.controller.TICK` it renews the drive lease
(``controller.tick``) — if this loop ever stalls, the lease lapses and the
network side stops the robot — and a slower one refreshes ages (stale values,
picture age).

Banners have topics (see ``banners``): the connection's life (connecting,
connected, failed, lost → reconnecting (n)) is drawn from the model into ONE
``link`` banner updated in place; notices (:class:`rtmu.notices.Notice`) are
routed by their kind — connection notices fold into that banner, speed into the
speed banner, camera into the camera page — never by the words in their text; a
deliberate disconnect shows nothing.
"""

from __future__ import annotations

import concurrent.futures
import functools
import time
from collections.abc import Callable, Mapping

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
gi.require_version("Gdk", "4.0")
from gi.repository import Gdk, Gio, GLib, Gtk, Pango  # noqa: E402

from ..client.custom_commands import ServerCommand  # noqa: E402
from ..commands import COMMANDS, CommandState, action_name  # noqa: E402
from ..controller import TICK, SecretStore  # noqa: E402
from ..fleet import RobotSession  # noqa: E402
from ..guardian.handle import BEAT_PERIOD as GUARDIAN_BEAT  # noqa: E402
from ..model import (  # noqa: E402
    SPEED_MAX,
    SPEED_MIN,
    ConnectionState,
    MapModel,
    OperatorState,
    Phase,
    RobotModel,
    RobotState,
    SpeedSetting,
)
from ..notices import Kind, Level, Notice  # noqa: E402
from ..settings import Profile  # noqa: E402
from .banners import BannerStack  # noqa: E402
from .bars import FullscreenBar, connect_button, menu_button, show_connection, stop_button  # noqa: E402
from .bridge_toggle import BridgeToggle  # noqa: E402
from .camera import CameraView, PictureDecoder  # noqa: E402
from .config_page import ConfigPage  # noqa: E402
from .details import DetailsWindow  # noqa: E402
from .dpad import DPad  # noqa: E402
from .goals_panel import GoalsPanel  # noqa: E402
from .handheld import Handheld  # noqa: E402
from .keys import KeyRouter  # noqa: E402
from .layers import LayersPanel  # noqa: E402
from .live_video import LiveVideoControls  # noqa: E402
from .mapview import MapStage  # noqa: E402
from .motion import MotionIndicator  # noqa: E402
from .move_dialogs import go_dialog, turn_dialog  # noqa: E402
from .nav_draw import Marker, MarkerKind  # noqa: E402
from .nav_text import link_lost_note  # noqa: E402
from .notes import map_note  # noqa: E402
from .palette import CommandPalette  # noqa: E402
from .pip import PictureInPicture  # noqa: E402
from .popups import PopupStack  # noqa: E402
from .pose_bar import PoseBar  # noqa: E402
from .pose_pick import PosePicker  # noqa: E402
from .ptz_controls import PtzControls  # noqa: E402
from .routes_panel import RoutesPanel  # noqa: E402
from .selected_model import SelectedModel  # noqa: E402
from .settings_dialog import ConnectionDialog, PasswordPrompt  # noqa: E402
from .shortcuts import build_shortcuts_window  # noqa: E402
from .split_view import SplitView  # noqa: E402
from .toolbar import StatusToolbar  # noqa: E402
from .viewport import zoom_label  # noqa: E402

REFRESH_EVERY = 3
"""Ticks between refreshes of ages (toolbar, picture): 0.3 s."""
LOOP_LAG_WARN = 0.5
"""Seconds without a network-loop heartbeat after which the window warns that drive commands (and
stops) are not going out; the warning goes once the lag is under half of this again."""


def touch_only(display: Gdk.Display | None = None) -> bool:
    """True when the only pointing device is a touchscreen (a tablet): then the D-pad shows by default."""
    display = display or Gdk.Display.get_default()
    seat = display.get_default_seat() if display is not None else None
    if seat is None:
        return False
    caps = seat.get_capabilities()
    if not caps & Gdk.SeatCapabilities.TOUCH:
        return False
    pointers = [
        d
        for d in seat.get_devices(Gdk.SeatCapabilities.POINTER)
        if d.get_source() in (Gdk.InputSource.MOUSE, Gdk.InputSource.TOUCHPAD, Gdk.InputSource.TRACKPOINT)
    ]
    return not pointers


WINDOW_ROBOT_MENU = (
    ("Camera picture", "win.camera", "request_image"),
    ("Safe drive", "win.safe-drive", "safe_drive_on"),
)
"""The robot menu's window entries after the registry's menu commands: label, action, and the command
whose state enables it (the camera page and the safe-drive switch are the window's, not commands)."""


def short_reason(reason: str) -> str:
    """A reason short enough for a menu row ("this server does not offer X" → "not offered by the server")."""
    if reason.startswith(("this server does not offer", "this server offers no")):
        return "not offered by the server"
    return reason or "unavailable"


def _unset(action: Gio.SimpleAction) -> None:
    action.set_state(GLib.Variant.new_boolean(False))


def _flag(action: Gio.SimpleAction) -> bool:
    """A boolean action's state (False before it has one)."""
    state = action.get_state()
    return state is not None and state.get_boolean()


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
        self.profiles = dict(profiles or {})
        self.keyring_available = keyring_available
        self._profile_saved = profile_saved
        self._passwords: dict[str, str] = {}
        self.ticks = 0
        """Counts timer ticks: proof for tests that the main loop is alive."""
        self._states: dict[str, CommandState] = {}
        self._dialog: Gtk.Window | None = None

        link = session.runner
        self._link = link
        status_age = lambda: self._link.status_age()  # noqa: E731 - the shown robot's, also after a switch
        self.banners = BannerStack()
        self.stage = MapStage(model, operator, clock=clock, status_age=status_age)
        self.stage.on_view_changed = self._view_changed
        self.toolbar = StatusToolbar(model, operator, clock=clock, status_age=status_age)
        self.camera = CameraView(on_request=self._request_picture, on_back=self.show_map, clock=clock)
        self.inset = PictureInPicture(self.show_camera, clock=clock, on_hide=lambda: self._hide_inset())
        self.ptz = PtzControls(model, link, on_moved=self._request_picture)
        self.ptz.attach_drag(self.camera.picture)
        self.camera.append(self.ptz)
        self.live = LiveVideoControls(
            self.camera, start=link.start_video, stop=link.stop_video, pause=link.pause_video,
            tell=lambda level, text: self.banners.tell("camera", level, text, timeout=5.0),
        )  # fmt: skip
        self.decoder = PictureDecoder(self._picture_decoded)
        self.dpad = DPad(hold=self._hold, release=self._release, stop=self._stop_from_dpad)
        self.keys = KeyRouter(
            hold=self._hold, release=self._release, command=self._command, view=self.view_intent
        )
        self.add_controller(self.keys.controller)

        self._build()
        self.controller = session.controller
        if secrets is not None:
            self.controller.secrets = secrets
        self.robot_view = _View(self)
        session.attach_view(self.robot_view)
        self.controller.select_profile(profile)
        self._set_speed_from_profile(profile)
        self._install_actions()
        self.set_help_overlay(build_shortcuts_window())

        self._unobserve = [
            model.connection.observe(self._on_connection),
            operator.speed.observe(self._on_speed),
            model.camera.observe(self._on_camera),
            model.map.observe(self._on_map),
            model.robot.observe(self._on_robot),
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
        self._view_changed()

    # -- layout ------------------------------------------------------------------------------
    def _build(self) -> None:
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
        self.menu_model = self._menu()
        self.menu_button = menu_button(self.menu_model)
        header.pack_end(self.menu_button)
        self.camera_button = Gtk.ToggleButton(icon_name="camera-photo-symbolic")
        self.camera_button.set_focusable(False)
        self.camera_button.set_tooltip_text("Camera picture (Esc)")
        self.camera_button.connect("clicked", self._camera_button_clicked)
        header.pack_end(self.camera_button)
        self.routes_panel = RoutesPanel(self.model, self.send_data)  # only when the server lists getRoutes
        header.pack_end(self.routes_panel)
        goto = self._goto_goal  # the panel shows only when the server navigates (goals, points, dock)
        self.goals_panel = GoalsPanel(
            self.model, goto=goto, run=self._command, pick=self.start_pick, stop=self.stop_now
        )
        header.pack_end(self.goals_panel)
        self.set_titlebar(header)

        self.toolbar_revealer = Gtk.Revealer(transition_type=Gtk.RevealerTransitionType.SLIDE_DOWN)
        self.toolbar_revealer.set_transition_duration(120)
        self.toolbar_revealer.set_child(self.toolbar)
        self.toolbar_revealer.set_reveal_child(True)

        self.map_page = map_page = Gtk.Overlay()
        map_page.set_child(self.stage)
        map_page.add_overlay(self._osd())
        map_page.add_overlay(self.dpad)
        map_page.add_overlay(self.inset)
        self.motion = MotionIndicator(self.model, held=self._drive_held)
        map_page.add_overlay(self.motion)
        self.picker = PosePicker(self.stage, changed=lambda: self.pose_bar.update())
        self.pose_bar = PoseBar(self.picker, self._pose_confirmed)
        map_page.add_overlay(self.pose_bar)
        # Server popups: cards over the map above the zoom buttons, never focusable (STOP is in the header).
        self.popup_stack = PopupStack(self.model.popups, self._answer_popup, clock=self.clock)
        map_page.add_overlay(self.popup_stack)
        self.layers = LayersPanel(self.model.drawings, self.model.connection, self._link)  # View → Layers…
        map_page.add_overlay(self.layers)
        self.map_note = Gtk.Label(halign=Gtk.Align.CENTER, valign=Gtk.Align.END, visible=False)
        self.map_note.add_css_class("map-note")
        self.map_note.set_margin_bottom(62)  # above the zoom buttons, which a narrow window puts under it
        self.map_note.set_margin_start(12)
        self.map_note.set_margin_end(12)
        self.map_note.set_wrap(True)
        self.map_note.set_max_width_chars(60)
        self.map_note.set_justify(Gtk.Justification.CENTER)
        self.map_note.set_use_markup(False)
        self.map_note.set_can_target(False)
        map_page.add_overlay(self.map_note)
        self.dpad.set_visible(touch_only())
        self.inset.place(corner_free=not self.dpad.get_visible())
        self.stage.connect("resize", lambda _s, width, _h: self.inset.fit_to(width))

        self.stack = Gtk.Stack(transition_type=Gtk.StackTransitionType.NONE)
        self.split = SplitView(map_page)  # the map page, and the live picture beside it while split
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

    def _osd(self) -> Gtk.Widget:
        """Zoom −/label/+, Fit and Follow: big enough for a thumb, over the map's bottom right."""
        osd = Gtk.Box(spacing=2, halign=Gtk.Align.END, valign=Gtk.Align.END)
        osd.add_css_class("map-osd")
        osd.set_margin_end(10)
        osd.set_margin_bottom(10)

        def button(icon: str, tip: str, fn: Callable[[], None]) -> Gtk.Button:
            b = Gtk.Button(icon_name=icon, tooltip_text=tip)
            b.add_css_class("flat")
            b.set_focusable(False)
            b.connect("clicked", lambda _b: fn())
            return b

        osd.append(button("zoom-out-symbolic", "Zoom out (Ctrl+minus)", self.stage.zoom_out))
        self.zoom_label = Gtk.Label(label="100 %")
        self.zoom_label.add_css_class("zoom-label")
        osd.append(self.zoom_label)
        osd.append(button("zoom-in-symbolic", "Zoom in (Ctrl+plus)", self.stage.zoom_in))
        osd.append(button("zoom-fit-best-symbolic", "Fit map (Ctrl+0)", self.stage.fit))
        self.follow_button = Gtk.ToggleButton(
            icon_name="find-location-symbolic", tooltip_text="Follow the robot (F)"
        )
        self.follow_button.add_css_class("flat")
        self.follow_button.set_focusable(False)
        self.follow_button.set_active(self.stage.follow)
        self.follow_button.connect("toggled", self._follow_toggled)
        osd.append(self.follow_button)
        return osd

    def _menu(self) -> Gio.Menu:
        """The robot's commands, then one section for the rest (view switches in a submenu): two
        sections and one separator, so it still fits an 800×480 screen as the robot's rows grow."""
        menu = Gio.Menu()
        self.robot_menu = Gio.Menu()
        self._fill_robot_menu()
        menu.append_section(None, self.robot_menu)
        view = Gio.Menu()
        view.append("Status toolbar", "win.toolbar")
        view.append("Full screen", "win.fullscreen")
        view.append("Touch D-pad", "win.dpad")
        view.append("Alarm sound", "win.alarm-sound")
        view.append("Camera inset on the map", "win.inset")
        view.append("Split view: map and video", "win.split")
        view.append("Camera field of view", "win.fov")
        view.append("Sonar readings", "win.sonar")
        view.append("Layers…", "win.layers")
        view.append("Robot details…", "win.details")
        view.append("Foxglove bridge (ws://127.0.0.1:8765)", "win.foxglove")
        app = Gio.Menu()
        server = Gio.Menu()  # the connection and the server's own settings: one row, so the menu still fits
        server.append("Connection settings…", "win.settings")
        server.append("Configuration…", "win.server-config")
        app.append_submenu("Server", server)
        app.append_submenu("View", view)
        app.append("Keyboard shortcuts", "win.show-help-overlay")
        app.append("About RTMU", "win.about")
        app.append("Quit", "app.quit")
        menu.append_section(None, app)
        return menu

    def _fill_robot_menu(self) -> None:
        """The robot's commands; a greyed one says why (GTK menus have no tooltips): "… — not connected"."""
        entries = [(c.label, f"win.{action_name(c.name)}", c.name) for c in COMMANDS if c.menu]
        items = []
        for label, action, command in (*entries, *WINDOW_ROBOT_MENU):
            found = self.lookup_action(action.removeprefix("win."))
            state = self._states.get(command)
            if found is not None and not found.get_enabled() and state is not None:
                label = f"{label} — {short_reason(state.reason)}"
            items.append((label, action))
        shown = []
        for i in range(self.robot_menu.get_n_items()):
            value = self.robot_menu.get_item_attribute_value(i, "label", None)
            shown.append(value.get_string() if value is not None else "")
        if shown == [label for label, _ in items]:
            return
        self.robot_menu.remove_all()
        for label, action in items:
            self.robot_menu.append(label, action)

    def _install_actions(self) -> None:
        def plain(name: str, fn: Callable[[], None]) -> Gio.SimpleAction:
            action = Gio.SimpleAction.new(name, None)
            action.connect("activate", lambda _a, _p: fn())
            self.add_action(action)
            return action

        def toggle(name: str, initial: bool, fn: Callable[[bool], None]) -> Gio.SimpleAction:
            action = Gio.SimpleAction.new_stateful(name, None, GLib.Variant.new_boolean(initial))

            def flip(a: Gio.SimpleAction, _p: object) -> None:
                new = not _flag(a)
                a.set_state(GLib.Variant.new_boolean(new))
                fn(new)

            action.connect("activate", flip)
            self.add_action(action)
            return action

        # One action per command of the registry (held drive keys excepted: they have no "activate").
        # Disconnect also cancels an attempt in progress: its command is enabled while connecting.
        for cmd in COMMANDS:
            if not cmd.hold:
                plain(action_name(cmd.name), functools.partial(self._command, cmd.name))
        plain("settings", self.open_settings)
        plain("camera", lambda: self.view_intent("toggle_camera"))
        plain("about", self.show_about)
        plain("details", self.show_details)
        plain("server-config", self.show_server_config)
        plain("layers", self.layers.open)
        self.toolbar_action = toggle("toolbar", True, self.toolbar_revealer.set_reveal_child)
        self.fullscreen_action = toggle("fullscreen", False, self._set_fullscreen)
        self.dpad_action = toggle("dpad", self.dpad.get_visible(), self._set_dpad)
        self.inset_action = toggle("inset", True, self.inset.set_enabled)
        self.split_action = toggle("split", False, self._set_split)
        self.fov_action = toggle("fov", True, self._set_fov)
        self.sonar_action = toggle("sonar", self.operator.view.value.show_sonar, self._set_sonar)
        self.safe_action = toggle("safe-drive", True, self._set_safe_drive)
        self.foxglove = BridgeToggle(self.session, self.show_notice)  # publishing only, never drives
        self.foxglove_action = toggle("foxglove", False, self.foxglove.set)
        self.foxglove.failed = functools.partial(_unset, self.foxglove_action)  # a busy port: unchecked again
        self.connect("notify::fullscreened", self._fullscreen_changed)

    # -- the controller's View -----------------------------------------------------------------
    def show_notice(self, notice: Notice) -> None:
        """Show a controller/network message where its kind belongs (never routed by its words)."""
        kind, level, text = notice.kind, notice.level, notice.text
        phase = self.model.connection.value.phase
        if kind is Kind.CONNECTION or (text and text == self.model.connection.value.error):
            return  # the link banner shows the connection's life from the model
        if kind is Kind.LINK:
            if level is Level.INFO:
                self.banners.tell("link", "info", text, timeout=4.0)
            elif phase is Phase.CONNECTED:
                self.banners.tell("link", level.value, text, timeout=None)
        elif kind is Kind.SPEED_LIMIT:
            pct = self.operator.speed.value.percent
            limit = "maximum" if pct >= SPEED_MAX else "minimum"
            self.banners.tell("speed", "warning", f"Speed at its {limit}: {pct} %", timeout=2.5,
                              fraction=pct / SPEED_MAX)  # fmt: skip
        elif kind is Kind.SPEED:
            return  # the speed banner follows the model
        elif kind is Kind.NAVIGATION:  # outcomes and cancellations: one banner, updated in place
            self.banners.tell("navigation", level.value, text, timeout=8.0 if level is Level.INFO else 12.0)
        elif kind is Kind.CAMERA:
            if self.camera.waiting:
                self.camera.failed(text)
            self.banners.tell("camera", level.value, text, timeout=5.0)
        else:
            self.banners.tell(
                f"notice:{text}", level.value, text, timeout=6.0 if level is Level.ERROR else 4.0
            )

    def commands_changed(self, states: Mapping[str, CommandState]) -> None:
        self._states.update(states)
        self.goals_panel.commands_changed(states)
        for name, state in states.items():
            label = COMMANDS.get(name).label if name in COMMANDS else name
            self.dpad.set_command_state(name, state.enabled, state.reason, label)
            self._enable(action_name(name), state.enabled)
            if name == "request_image":
                self.camera_button.set_sensitive(
                    state.enabled or self.stack.get_visible_child_name() == "camera"
                )
                self.camera_button.set_tooltip_text(
                    "Camera picture (Esc)" if state.enabled else f"Camera picture: {state.reason}"
                )
                self.camera.set_available(state.enabled, state.reason)
                self._enable("camera", state.enabled or self.stack.get_visible_child_name() == "camera")
            elif name == "safe_drive_on":
                self._enable("safe-drive", state.enabled)
        shown = {c.name for c in COMMANDS if c.menu} | {name for _label, _action, name in WINDOW_ROBOT_MENU}
        if shown & set(states):
            self._fill_robot_menu()

    def ask_password(self, profile: Profile, answer: Callable[[str | None], None]) -> None:
        remembered = self._passwords.get(profile.name)
        if remembered is not None:
            answer(remembered)
            return
        prompt = PasswordPrompt(self, profile, answer)
        prompt.present()

    def command_state(self, name: str) -> CommandState:
        return self._states.get(name, CommandState(False, "unknown command"))

    def _enable(self, action: str, enabled: bool) -> None:
        a = self.lookup_action(action)
        if isinstance(a, Gio.SimpleAction):
            a.set_enabled(enabled)

    def show_session(self, session: RobotSession) -> None:
        """Show another robot of the fleet (which has already stopped the one shown before).

        Keys held now stay held in the key router, so their auto-repeat is swallowed: the new
        robot moves only on a fresh press. A finger on the D-pad is let go of.
        """
        self.dpad.release_all()
        self.picker.cancel()
        self.session, self.controller, self._link = session, session.controller, session.runner
        self.handheld.show_controller(self.controller)  # the pad follows the selection, never carries over
        session.attach_view(self.robot_view)
        if isinstance(self.model, SelectedModel):
            self.model.show(session.state)
        self.camera.clear()
        self.inset.show_texture(None)
        self.commands_changed(self.controller.command_states())
        self._update_header(self.model.connection.value)

    # -- intents -------------------------------------------------------------------------------
    def _hold(self, name: str) -> None:
        # On the camera page too: the picture shows its age, and a fresh press is the operator's intent.
        self.controller.run(name)

    def _release(self, name: str) -> None:
        self.controller.release_command(name)

    def _stop_from_dpad(self) -> None:
        self.controller.run("stop")

    def _beat(self) -> bool:
        """The GTK thread's heartbeat to the guardian; True keeps the timer."""
        self._link.ui_heartbeat()
        return True

    def _command(self, name: str) -> None:
        """A command from a key, the menu or a button: refused with its reason while shown disabled."""
        state = self._states.get(name)
        if state is not None and not state.enabled:
            label = COMMANDS.get(name).label.rstrip("…") if name in COMMANDS else name
            self.banners.tell(f"notice:{name}", "warning", f"{label}: {state.reason}", timeout=4.0)
            return
        self.controller.run(name)

    def view_intent(self, name: str) -> None:
        """Window-level intents from keys, menu and buttons."""
        if name == "toggle_camera" and self.picker.active:
            self.picker.cancel()  # Esc leaves a pick mode first
        elif name == "toggle_camera":
            if self.stack.get_visible_child_name() == "camera":
                self.show_map()
            else:
                self.show_camera(request=True)
        elif name == "zoom_in":
            self.stage.zoom_in()
        elif name == "zoom_out":
            self.stage.zoom_out()
        elif name == "zoom_fit":
            self.stage.fit()
        elif name == "follow":
            self.stage.set_follow(not self.stage.follow)
        elif name == "live_video":
            camera = self.command_state("request_image")
            if reason := self.live.toggle(camera.enabled, camera.reason):
                self.banners.tell("camera", "warning", f"Live video: {reason}", timeout=4.0)
        elif name.startswith("ptz_") and (reason := self.ptz.key(name)):
            self.banners.tell("ptz", "warning", f"Camera head: {reason}", timeout=4.0)

    def open_dialog(self, name: str) -> None:
        """The dialog a command asked for (the controller stopped the robot first)."""
        makers = {
            "turn": lambda: turn_dialog(self, self.controller.turn_by),
            "go": lambda: go_dialog(self, self.controller.move_distance),
            "commands": lambda: CommandPalette(self, self._link.list_commands, self._run_server_command),
        }
        dialog = makers[name]()
        dialog.present()

    def stop_now(self) -> None:
        """The on-screen STOP: the same as Space, and sent whatever the link looks like.

        Keys still held stay blocked by the controller until they are let go (as after Space), so
        their auto-repeat cannot start the robot again; a finger on the D-pad is let go of here.
        """
        self.controller.stop()
        self.dpad.release_all()
        self.picker.cancel()

    def _drive_held(self) -> bool:
        """A held drive is live (keys, D-pad or the pad's dead-man); False while the window is being built."""
        controller = getattr(self, "controller", None)
        return controller is not None and (bool(controller.held) or controller.analog_active)

    def _answer_popup(self, popup_id: int, button: int) -> None:
        self._link.answer_popup(popup_id, button)

    def _run_server_command(self, command: ServerCommand, argument: str | None) -> None:
        """From the palette: sent on the network thread; the outcome comes back as a banner."""

        def done(future: concurrent.futures.Future[bool]) -> None:
            if future.cancelled() or future.exception() is not None:
                return  # the runner already raised a Kind.COMMAND notice with the reason
            said = "taken by the server" if future.result() else "sent; the server did not answer"
            GLib.idle_add(self._tell_once, "server-command", f"{command.name}: {said}")

        self._link.run_command(command, argument).add_done_callback(done)

    def _tell_once(self, topic: str, text: str) -> bool:
        self.banners.tell(topic, "info", text, timeout=4.0)
        return False  # an idle callback: once

    def _goto_goal(self, goal: str) -> None:
        self.controller.goto_goal(goal)

    def start_pick(self, kind: MarkerKind) -> None:
        """Go to a point / set robot position: a map mode; the pose bar confirms (``pose_bar``)."""
        self.show_map()
        self.picker.start(kind)

    def _pose_confirmed(self, marker: Marker) -> None:
        if marker.kind is MarkerKind.GOTO:
            self.controller.goto_pose(marker.x, marker.y, marker.th)
        else:
            th = self.model.robot.value.th if marker.th is None else marker.th
            self.controller.localize(marker.x, marker.y, th)

    def toggle_connection(self) -> None:
        phase = self.model.connection.value.phase
        if phase in (Phase.DISCONNECTED, Phase.FAILED):
            self.connect_now()
        else:
            self.controller.disconnect()

    def connect_now(self) -> None:
        profile = self.controller.profile
        self.controller.connect(password=self._passwords.get(profile.name))

    def show_camera(self, request: bool = False) -> None:
        state = self.command_state("request_image")
        if request and not state.enabled:
            self.banners.tell("camera", "warning", f"Camera picture: {state.reason}", timeout=4.0)
            self.camera_button.set_active(False)
            return
        self.controller.stop()
        self.stack.set_visible_child_name("camera")
        self.camera_button.set_active(True)
        if request or self.camera.image is None:
            self._request_picture()

    def show_map(self) -> None:
        self.stack.set_visible_child_name("map")
        self.camera_button.set_active(False)
        self.commands_changed({"request_image": self.command_state("request_image")})

    def _camera_button_clicked(self, button: Gtk.ToggleButton) -> None:
        showing = self.stack.get_visible_child_name() == "camera"
        if button.get_active() != showing:
            self.view_intent("toggle_camera")

    def _request_picture(self) -> None:
        if self.controller.run("request_image"):
            self.camera.requesting()

    # -- model reactions ---------------------------------------------------------------------
    def _on_connection(self, old: ConnectionState, new: ConnectionState) -> None:
        where = f"{new.host}:{new.port}" if new.host else ""
        phase = new.phase
        if self.session.closed:  # a closed robot's late news (the fleet said why it went): no banner
            pass
        elif phase is Phase.CONNECTING and old.phase is not Phase.CONNECTING:
            self.banners.tell("link", "info", f"Connecting to {where}…", timeout=None)
        elif phase is Phase.CONNECTED and old.phase is not Phase.CONNECTED:
            if old.phase is Phase.RECONNECTING:
                self.banners.tell(
                    "link", "info", f"Reconnected to {where}: press a key to drive again", timeout=4.0
                )
            else:
                self.banners.tell("link", "info", f"Connected to {where}", timeout=3.0)
        elif phase is Phase.RECONNECTING:
            count = f" ({new.attempt})" if new.attempt else ""
            note = link_lost_note(self.model.navigation.value)
            self.banners.tell("link", "warning", f"Link lost — reconnecting{count}…{note}", timeout=None)
        elif phase is Phase.FAILED and (new.error != old.error or old.phase is not Phase.FAILED):
            lost = old.phase in (Phase.CONNECTED, Phase.RECONNECTING)
            reason = new.error or "no reason given"
            note = link_lost_note(self.model.navigation.value)
            text = f"Link lost: {reason}.{note}" if lost else f"Could not connect to {where}: {reason}"
            self.banners.tell("link", "error", text, timeout=10.0)
        elif phase is Phase.DISCONNECTED and old.phase is not Phase.DISCONNECTED:
            self.banners.dismiss("link")  # deliberate: no banner at all
        if phase is Phase.DISCONNECTED or (phase is Phase.CONNECTING and old.phase is not Phase.RECONNECTING):
            self.camera.clear()
            self.live.connection_lost()
            self.split.show_picture(None, None)
            if self.stack.get_visible_child_name() == "camera":
                self.show_map()
        # The inset is a glance at the robot's view: a picture from an earlier connection is not
        # one. Greyed (with its age) while the link is lost, gone once a new connection is made.
        if phase in (Phase.DISCONNECTED, Phase.CONNECTING) or (
            phase is Phase.CONNECTED and old.phase is not Phase.CONNECTED
        ):
            self.inset.show_texture(None)
        elif phase in (Phase.RECONNECTING, Phase.FAILED):
            self.inset.set_live(False)
        # Held keys stay held in the key router (their auto-repeat is swallowed); the controller
        # has blocked them, so only a fresh press drives after the link comes back.
        self._update_header(new)
        self._update_map_note()

    def _update_header(self, conn: ConnectionState) -> None:
        phase = conn.phase
        connected_ish = phase in (Phase.CONNECTED, Phase.CONNECTING, Phase.RECONNECTING)
        for button in (self.connect_button, self.fullscreen_bar.connect_button):
            show_connection(button, connected_ish)
        self._enable("connect", not connected_ish)
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
        self._update_map_note()
        self._update_header(self.model.connection.value)

    def _update_map_note(self) -> None:
        """The note under the map, from the connection phase and the map (``notes.map_note``)."""
        text = map_note(self.model.connection.value, self.model.map.value)
        if self.map_note.get_text() != text:
            self.map_note.set_text(text)
        self.map_note.set_visible(bool(text))

    def _on_robot(self, old: RobotState, new: RobotState) -> None:
        if new.safe_drive is not None and new.safe_drive != old.safe_drive:
            self.safe_action.set_state(GLib.Variant.new_boolean(new.safe_drive))

    def _on_speed(self, _old: SpeedSetting, new: SpeedSetting) -> None:
        self.banners.tell(
            "speed", "info", f"Speed {new.percent} %", timeout=2.5, fraction=new.percent / SPEED_MAX
        )

    def _hide_inset(self) -> None:
        if _flag(self.inset_action):
            self.inset_action.activate(None)

    def _set_split(self, on: bool) -> None:
        """Map and video side by side: the split starts live video (the pane would show nothing else)."""
        self.split.set_split(on)
        if on and not self.live.live and self.command_state("request_image").enabled:
            self.live.set_live(True)

    def _set_fov(self, on: bool) -> None:
        self.stage.show_fov = on
        self.stage.queue_draw()

    def _on_camera(self, _old: object, new: object) -> None:
        if new is not None:
            self.decoder.decode(new)  # type: ignore[arg-type]

    def _picture_decoded(
        self, image: object, textures: tuple[Gdk.Texture, Gdk.Texture] | None, error: str
    ) -> None:
        current = self.model.camera.value
        if getattr(image, "video", None) is not None:  # the next frame only once this one is painted
            shows = (self.camera.picture, self.inset, self.split.pane)
            seen = textures is not None and image is current and any(w.get_mapped() for w in shows)
            sequence: int = image.sequence  # type: ignore[attr-defined]
            self.live.when_painted(lambda: self._link.video_shown(sequence), seen)
        if current is None or image is not current:
            return  # a newer picture (or a disconnect) overtook this one
        self.camera.show_picture(image, None if textures is None else textures[0], error)
        if textures is not None:
            self.inset.show_texture(self.inset.texture_for(*textures), image.received_at)
            self.live.shown(image)
            self.split.show_picture(textures[0], image)

    def _view_changed(self) -> None:
        label = "Fit" if self.stage.fitted else ""
        self.zoom_label.set_text(
            zoom_label(self.stage.viewport.zoom)
            if not label
            else f"{label} {zoom_label(self.stage.viewport.zoom)}"
        )
        if self.follow_button.get_active() != self.stage.follow:
            self.follow_button.set_active(self.stage.follow)

    def _follow_toggled(self, button: Gtk.ToggleButton) -> None:
        if button.get_active() != self.stage.follow:
            self.stage.set_follow(button.get_active())

    # -- toggles -------------------------------------------------------------------------------
    def _set_fullscreen(self, on: bool) -> None:
        if on:
            self.fullscreen()
        else:
            self.unfullscreen()

    def leave_fullscreen(self) -> None:
        """The bar's way out (as F11): the request is recorded in the action's state at once."""
        self.fullscreen_action.set_state(GLib.Variant.new_boolean(False))
        self.unfullscreen()

    def _fullscreen_changed(self, *_a: object) -> None:
        state = self.is_fullscreen()
        self.fullscreen_bar.set_reveal_child(state)
        if _flag(self.fullscreen_action) != state:
            self.fullscreen_action.set_state(GLib.Variant.new_boolean(state))

    def _set_dpad(self, on: bool) -> None:
        self.dpad.set_visible(on)
        self.inset.place(corner_free=not on)  # the D-pad takes the bottom-left corner

    def _set_sonar(self, on: bool) -> None:
        self.operator.view.update(show_sonar=on)

    def _set_safe_drive(self, on: bool) -> None:
        self.controller.run("safe_drive_on" if on else "safe_drive_off")

    def set_toolbar_visible(self, on: bool) -> None:
        self.toolbar_revealer.set_reveal_child(on)
        self.toolbar_action.set_state(GLib.Variant.new_boolean(on))

    def _set_speed_from_profile(self, profile: Profile) -> None:
        pct = max(SPEED_MIN, min(SPEED_MAX, profile.speed // 10 * 10))
        self.operator.speed.set(SpeedSetting(pct))

    # -- dialogs -------------------------------------------------------------------------------
    def open_settings(self) -> None:
        profiles = dict(self.profiles)
        current = self.controller.profile
        profiles.setdefault(current.name, current)
        dialog = ConnectionDialog(
            self, profiles, current, on_save=self._settings_saved, keyring_available=self.keyring_available
        )
        self._dialog = dialog
        dialog.present()

    def _settings_saved(self, profile: Profile, password: str | None) -> None:
        self.profiles[profile.name] = profile
        if password is not None:
            self._passwords[profile.name] = password
        if self._profile_saved is not None:
            self._profile_saved(profile, password)
        changed = profile != self.controller.profile
        self.controller.select_profile(profile)
        self._update_header(self.model.connection.value)
        if changed and self.model.connection.value.phase is not Phase.DISCONNECTED:
            self.banners.tell(
                "notice:saved", "info", f"Saved “{profile.name}”: reconnect to use it", timeout=4.0
            )

    def send_data(self, name: str, payload: object) -> None:
        """Fire-and-forget request of an LD panel (patrol, say) through the controller's link."""
        self.controller.link.command(name, payload)

    def show_server_config(self) -> None:
        """The server's configuration page (its own window, so typing there never drives): one at a time."""
        page = getattr(self, "config_page", None)
        if page is None or page.closed:
            link = self._link
            self.config_page = ConfigPage(
                self, link.fetch_config, link.set_config, lambda fn: setattr(link, "on_config_updated", fn)
            )
        self.config_page.present()

    def show_details(self) -> None:
        """The details window (DataStore strings, docking, say): one at a time."""
        details = getattr(self, "details", None)
        if details is None or not details.get_visible():
            self.details = DetailsWindow(self, self.model, self.send_data, self._link.watch_strings)
        self.details.present()

    def show_about(self) -> None:
        from .. import __version__

        about = Gtk.AboutDialog(
            transient_for=self,
            modal=True,
            program_name="RTMU",
            version=__version__,
            comments="Robot Teleoperation, Mobile User interface: drive an ARIA (ArNetworking) robot "
            "from a tablet or a laptop.",
            logo_icon_name="io.github.rtmu.Rtmu",
            license_type=Gtk.License.MIT_X11,
        )
        about.present()

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
        self.controller.focus_lost(
            "RTMU was suspended (Ctrl+Z)" if keep_focus else "the window lost the keyboard"
        )
        self.keys.release_all()
        self.dpad.release_all()
        if keep_focus and self.is_active():
            self.controller.focus_gained()

    def _tick(self) -> bool:
        self.ticks += 1
        self.controller.tick()
        self.motion.refresh()
        if self.ticks % REFRESH_EVERY == 0:
            self.toolbar.refresh()
            self.camera.tick()
            self.inset.tick()
            self._check_loop_lag()
            if self.stage.robot_is_stale() and self.model.robot.value.numbers_at is not None:
                self.stage.queue_draw()
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
        self.stage.close()
        self.toolbar.close()
        self.routes_panel.close()
        self.goals_panel.close()
        self.ptz.close()
        self.layers.unobserve()
        self.motion.close()
        self.decoder.close()
        self.foxglove.close()

"""The window's actions: a named ``win.*`` action for everything the window does on request, its menu,
and which of them are enabled.

* **Commands**: one action per command of the registry (``win.<name>``, underscores as hyphens;
  held drive keys excepted: they have no "activate"), enabled by its command state. Run from a key,
  the menu or a button, a command shown greyed is refused with its reason — a banner, never silence.
* **The window's own**: the camera page (``camera``, Esc), ``zoom-in`` / ``zoom-out`` / ``zoom-fit``
  and ``follow``, ``open-menu``, ``goto-panel``, ``select-robot(n)`` / ``next-robot`` /
  ``previous-robot``, ``live-video``, the camera head's moves (``ptz-left`` … ``ptz-home``) and the
  dialogs (``settings``, ``server-config``, ``details``, ``layers``, ``about``, ``why``, ``console``).
* **Switches** (stateful, so the menu shows their check marks): the View menu's ``toolbar``,
  ``fullscreen``, ``dpad``, ``inset``, ``split``, ``fov``, ``sonar``, ``foxglove``, and ``safe-drive``.
* **The menu**: the robot's commands first (a greyed row says why: GTK menus have no tooltips),
  then "Why won't it move?", Server, View, Help (the keys, About) and Quit; every row shows its key
  from the one key table (``keys.menu_item``).

Keys reach an action through :meth:`WindowActions.activate` (``keys.KeyRouter``), the menu and the
buttons through GTK's own activation: one table says key → action (``keys``), the keys window
and the menu read it. STOP is not here: Space is caught before any of this on every surface
(``stop_keys``), and the STOP buttons call the window's ``stop_now`` directly.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from typing import Any

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gio, GLib  # noqa: E402

from ..base.i18n import N_, _  # noqa: E402
from ..client.config_feed import ConfigApi, config_api  # noqa: E402
from ..control.commands import COMMANDS, CommandState, action_name  # noqa: E402
from ..model.observables import ConnectionState, RobotState  # noqa: E402
from .keys import menu_item  # noqa: E402
from .state_words import reason_words  # noqa: E402

MainWindow = Any
"""``ui.window.MainWindow`` (which imports this module): named, not imported."""

WINDOW_ROBOT_MENU = (
    (N_("Camera picture"), "win.camera", "request_image"),
    (N_("Safe drive"), "win.safe-drive", "safe_drive_on"),
)
"""The robot menu's window entries after the registry's menu commands: label, action, and the command
whose state enables it (the camera page and the safe-drive switch are the window's, not commands)."""
PTZ_MOVES = ("ptz_left", "ptz_right", "ptz_up", "ptz_down", "ptz_zoom_in", "ptz_zoom_out", "ptz_home")
"""The camera head's moves, each an action (``win.ptz-left`` …): its keys and the camera bar's buttons."""
PICK_TURNS = ("ptz_left", "ptz_right")
"""In a pick mode these keys turn the picked heading instead of the camera head (``keyboard_nav``)."""
UNKNOWN = CommandState(False, N_("unknown command"))


def short_reason(reason: str) -> str:
    """A reason short enough for a menu row ("this server does not offer X" → "not offered by the server")."""
    if reason.startswith(("this server does not offer", "this server offers no")):
        return _("not offered by the server")
    return reason_words(reason) if reason else _("unavailable")


def flag(action: Gio.SimpleAction) -> bool:
    """A boolean action's state (False before it has one)."""
    state = action.get_state()
    return state is not None and state.get_boolean()


def set_flag(action: Gio.SimpleAction, on: bool) -> None:
    action.set_state(GLib.Variant.new_boolean(on))


Run = Callable[[GLib.Variant | None], None]


class WindowActions:
    """See the module notes. Built with the window (the menu first: the header shows it); the actions
    are added by :meth:`install` once the parts they run exist."""

    def __init__(self, window: MainWindow) -> None:
        self.window = window
        self.states: dict[str, CommandState] = {}
        """The command states last heard from the controller."""
        self._run: dict[str, Run] = {}
        """action name → what it does (also for a key while the action is shown greyed)."""
        self._unobserve: list[Callable[[], None]] = []
        self.menu_model = self._menu()

    # -- the actions -----------------------------------------------------------------------------
    def install(self) -> None:
        w = self.window
        for cmd in COMMANDS:  # Disconnect also cancels an attempt: it is enabled while connecting
            if not cmd.hold:
                self._plain(action_name(cmd.name), functools.partial(self.run_command, cmd.name))
        self._plain("camera", self._camera)
        self._plain("settings", w.dialogs.open_settings)
        self._plain("server-config", w.dialogs.show_server_config)
        self._plain("files", w.commissioning.show_files)
        self._plain("scan", w.commissioning.scan)
        self._plain("map-edit", w.commissioning.edit_map)
        self._plain("details", w.dialogs.show_details)
        self._plain("about", w.dialogs.show_about)
        self._plain("why", w.dialogs.show_why)
        self._plain("console", lambda: w.dialogs.show_console())
        self._plain("layers", w.layers.open)
        # The map.
        self._plain("zoom-in", w.stage.zoom_in)
        self._plain("zoom-out", w.stage.zoom_out)
        self._plain("zoom-fit", w.stage.fit)
        self.follow_action = self._add("follow", lambda _p: w.map_page.toggle_follow(), w.stage.follow)
        w.map_page.on_follow = functools.partial(self._show_flag, self.follow_action)
        # The keyboard's ways around the window and the fleet (``keyboard_nav``: created after this).
        self._plain("open-menu", lambda: w.keyboard.open_menu())
        self._plain("goto-panel", lambda: w.keyboard.open_goto())
        self._add("select-robot", lambda p: w.keyboard.select(p.get_int32() if p else 0), param="i")
        self._plain("next-robot", lambda: w.keyboard.step(1))
        self._plain("previous-robot", lambda: w.keyboard.step(-1))
        # The camera.
        self._plain("live-video", w.camera_page.live_key)
        for move in PTZ_MOVES:
            self._plain(action_name(move), functools.partial(self._ptz, move))
        # The switches.
        self.toolbar_action = self._toggle("toolbar", True, w.toolbar_revealer.set_reveal_child)
        self.fullscreen_action = self._toggle("fullscreen", False, self._set_fullscreen)
        self.dpad_action = self._toggle("dpad", w.dpad.get_visible(), w.map_page.set_dpad)
        self.inset_action = self._toggle("inset", True, w.inset.set_enabled)
        self.split_action = self._toggle("split", False, w.camera_page.set_split)
        self.fov_action = self._toggle("fov", True, w.map_page.set_fov)
        sonar = w.operator.view.value.show_sonar
        self.sonar_action = self._toggle("sonar", sonar, lambda on: w.operator.view.update(show_sonar=on))
        self.safe_action = self._toggle("safe-drive", True, self._set_safe_drive)
        self.foxglove_action = self._toggle("foxglove", False, w.foxglove.set)
        w.foxglove.failed = functools.partial(set_flag, self.foxglove_action, False)  # a busy port: unchecked
        w.connect("notify::fullscreened", self._fullscreen_changed)
        self._unobserve = [
            w.model.robot.observe(self._on_robot),
            w.model.connection.observe(self._on_connection),
        ]
        self.fill_server_menu(config_api(w.model.connection.value.offers))

    def close(self) -> None:
        for remove in self._unobserve:
            remove()
        self._unobserve = []

    def _add(
        self, name: str, run: Run, state: bool | None = None, *, param: str | None = None
    ) -> Gio.SimpleAction:
        kind = None if param is None else GLib.VariantType.new(param)
        if state is None:
            action = Gio.SimpleAction.new(name, kind)
        else:
            action = Gio.SimpleAction.new_stateful(name, kind, GLib.Variant.new_boolean(state))
        action.connect("activate", lambda _a, p: run(p))
        self.window.add_action(action)
        self._run[name] = run
        return action

    def _plain(self, name: str, fn: Callable[[], None]) -> Gio.SimpleAction:
        return self._add(name, lambda _p: fn())

    def _toggle(self, name: str, initial: bool, fn: Callable[[bool], None]) -> Gio.SimpleAction:
        def flip(_p: GLib.Variant | None) -> None:
            new = not flag(action)
            set_flag(action, new)
            fn(new)

        action = self._add(name, flip, initial)
        return action

    # -- running them ----------------------------------------------------------------------------
    def activate(self, detailed: str) -> bool:
        """Run the action a key names (``win.zoom-in``, ``win.select-robot(3)``) — also while it is
        shown greyed: what it runs says why it cannot (a command's reason), as a key press deserves
        an answer. False when the window has no such action."""
        _ok, name, target = Gio.Action.parse_detailed_name(detailed)
        run = self._run.get(name.removeprefix("win."))
        if run is None:
            return False
        run(target)
        return True

    def run_command(self, name: str) -> None:
        """A command from a key, the menu or a button: refused with its reason while shown disabled."""
        state = self.states.get(name)
        if state is not None and not state.enabled:
            label = _(COMMANDS.get(name).label).rstrip("…") if name in COMMANDS else name
            self.window.banners.tell(
                f"notice:{name}",
                "warning",
                _("{command}: {reason}").format(command=label, reason=reason_words(state.reason)),
                timeout=4.0,
            )
            return
        self.window.controller.run(name)

    def command_state(self, name: str) -> CommandState:
        return self.states.get(name, UNKNOWN)

    def _camera(self) -> None:
        """Esc and the camera button: a pick mode ends first, then the Layers panel closes; else
        camera ⇄ map."""
        w = self.window
        if w.picker.active:
            w.picker.cancel()
        elif w.layers.get_visible():
            w.layers.close()
        else:
            w.camera_page.toggle()

    def _ptz(self, move: str) -> None:
        if move in PICK_TURNS and self.window.keyboard.pick_key(move):
            return  # a pick mode's Ctrl+Left/Right turn its heading
        self.window.camera_page.ptz_key(move)

    # -- enabling --------------------------------------------------------------------------------
    def enable(self, name: str, enabled: bool) -> None:
        action = self.window.lookup_action(name)
        if isinstance(action, Gio.SimpleAction):
            action.set_enabled(enabled)

    def commands_changed(self, states: Mapping[str, CommandState]) -> None:
        """Command states → the actions' enabling and the robot menu's greyed rows."""
        self.states.update(states)
        for name, state in states.items():
            self.enable(action_name(name), state.enabled)
            if name == "request_image":  # the camera button also brings the map back
                self.enable("camera", state.enabled or self.window.camera_page.showing)
            elif name == "safe_drive_on":
                self.enable("safe-drive", state.enabled)
        shown = {c.name for c in COMMANDS if c.menu} | {name for _label, _action, name in WINDOW_ROBOT_MENU}
        if shown & set(states):
            self.fill_robot_menu()

    # -- switches kept in step -------------------------------------------------------------------
    @staticmethod
    def _show_flag(action: Gio.SimpleAction, on: bool) -> None:
        if flag(action) != on:
            set_flag(action, on)

    def _on_robot(self, old: RobotState, new: RobotState) -> None:
        if new.safe_drive is not None and new.safe_drive != old.safe_drive:
            set_flag(self.safe_action, new.safe_drive)

    def _set_safe_drive(self, on: bool) -> None:
        self.window.controller.run("safe_drive_on" if on else "safe_drive_off")

    def hide_inset(self) -> None:
        """The inset's ×: the View menu's switch goes off with it."""
        if flag(self.inset_action):
            self.inset_action.activate(None)

    def _set_fullscreen(self, on: bool) -> None:
        if on:
            self.window.fullscreen()
        else:
            self.window.unfullscreen()

    def leave_fullscreen(self) -> None:
        """The full-screen bar's way out (as F11): the request is recorded in the action's state at once."""
        set_flag(self.fullscreen_action, False)
        self.window.unfullscreen()

    def _fullscreen_changed(self, *_a: object) -> None:
        state = self.window.is_fullscreen()
        self.window.fullscreen_bar.show_for(state, self.window.header)  # Go to and the camera go along
        self._show_flag(self.fullscreen_action, state)

    # -- the menu --------------------------------------------------------------------------------
    def _menu(self) -> Gio.Menu:
        """The robot's commands, then one section for the rest (view switches in a submenu): two
        sections and one separator, so it still fits an 800×480 screen as the robot's rows grow."""
        menu = Gio.Menu()
        self.robot_menu = Gio.Menu()
        self.fill_robot_menu()
        menu.append_section(None, self.robot_menu)
        self.view_menu = view = Gio.Menu()
        for label, action in (
            (_("Status toolbar"), "win.toolbar"),
            (_("Full screen"), "win.fullscreen"),
            (_("Touch D-pad"), "win.dpad"),
            (_("Alarm sound"), "win.alarm-sound"),
            (_("Camera inset on the map"), "win.inset"),
            (_("Split view: map and video"), "win.split"),
            (_("Camera field of view"), "win.fov"),
            (_("Sonar readings"), "win.sonar"),
            (_("Layers…"), "win.layers"),
            (_("Robot details…"), "win.details"),
            (_("Foxglove bridge ({url})").format(url="ws://127.0.0.1:8765"), "win.foxglove"),
        ):
            view.append_item(menu_item(label, action))
        self.app_menu = app = Gio.Menu()
        app.append_item(menu_item(_("Why won't it move?…"), "win.why"))
        self.server_menu = server = Gio.Menu()  # the connection and the server's own settings: one row
        self.fill_server_menu(ConfigApi.ARCONFIG)
        app.append_submenu(_("Server"), server)
        app.append_submenu(_("View"), view)
        helping = (
            Gio.Menu()
        )  # one row for both: "Why won't it move?" took a row, an 800×480 screen has no more
        helping.append_item(menu_item(_("Keyboard shortcuts"), "win.show-keys"))
        helping.append_item(menu_item(_("About RTMU"), "win.about"))
        app.append_submenu(_("Help"), helping)
        app.append_item(menu_item(_("Quit"), "app.quit"))
        menu.append_section(None, app)
        return menu

    def fill_server_menu(self, api: ConfigApi) -> None:
        """Server ▸ …: its Configuration row says which configuration API the robot has where RTMU
        cannot edit it yet (an Omron LD robot's), and that the console reads it."""
        config = _("Configuration…")
        if api is ConfigApi.OMRON_LD:
            config = _("Configuration… — {api}: not editable yet, see Console").format(api=api.value)
        items = (
            (_("Connection settings…"), "win.settings"),
            (config, "win.server-config"),
            (_("Console…"), "win.console"),
            (_("Files on the robot…"), "win.files"),  # commissioning (``ui.commissioning``)
            (_("Scan a map…"), "win.scan"),
            (_("Edit the map…"), "win.map-edit"),
        )
        menu = self.server_menu
        shown = [menu.get_item_attribute_value(i, "label", None) for i in range(menu.get_n_items())]
        if [v.get_string() if v is not None else "" for v in shown] == [label for label, _action in items]:
            return
        menu.remove_all()
        for label, action in items:
            menu.append_item(menu_item(label, action))

    def _on_connection(self, _old: ConnectionState, new: ConnectionState) -> None:
        self.fill_server_menu(config_api(new.offers))

    def fill_robot_menu(self) -> None:
        """The robot's commands; a greyed one says why (GTK menus have no tooltips): "… — not connected"."""
        entries = [(_(c.label), f"win.{action_name(c.name)}", c.name) for c in COMMANDS if c.menu]
        items = []
        for label, action, command in (*entries, *((_(w), a, c) for w, a, c in WINDOW_ROBOT_MENU)):
            found = self.window.lookup_action(action.removeprefix("win."))
            state = self.states.get(command)
            if found is not None and not found.get_enabled() and state is not None:
                label = _("{command} — {reason}").format(command=label, reason=short_reason(state.reason))
            items.append((label, action))
        shown = []
        for i in range(self.robot_menu.get_n_items()):
            value = self.robot_menu.get_item_attribute_value(i, "label", None)
            shown.append(value.get_string() if value is not None else "")
        if shown == [label for label, _action in items]:
            return
        self.robot_menu.remove_all()
        for label, action in items:
            self.robot_menu.append_item(menu_item(label, action))

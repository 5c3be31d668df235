"""Everything by keyboard: Tab moves a visible focus, F10 opens the menu, Ctrl+G the Go-to panel,
Alt+1…9 and Alt+Page Down / Page Up pick a robot of the fleet, and a pick mode takes arrow keys.

Safety first, as everywhere: the window's buttons take the focus now (Tab, with GTK's focus ring),
but no key they answer to is a drive or stop key — the stop keys (``stop_keys``, capture phase,
before anything else) and the drive keys (``keys.KeyRouter``, capture phase) are caught before a
focused button could see them, so Space never "clicks" a focused button: it stops. Return (or
Enter) activates the focused button.

The drawing of the map keeps its own keys (arrows drive), so a pick mode (Go to point, Set position)
gives the arrow keys a second meaning only while it is on and says so in its bar: they move the
picked point by about 20 pixels, Ctrl+Left/Right turn its heading by 15°, and Return confirms.
A robot of a fleet is picked with Alt+1…Alt+9 (its place in the list), Alt+Page Down (next) and
Alt+Page Up (previous); the menu lists them too, with their keys.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Gdk", "4.0")
from gi.repository import Gdk, Gio, GLib, Gtk  # noqa: E402

from ..base.i18n import _  # noqa: E402
from ..fleet.sessions import Fleet  # noqa: E402
from .keys import menu_item  # noqa: E402
from .nav_draw import Marker, MarkerKind  # noqa: E402
from .stop_keys import descendants  # noqa: E402

MainWindow = Any
"""``ui.window.MainWindow`` (which imports this module): named, not imported."""

FOCUSABLE = (Gtk.Button, Gtk.CheckButton, Gtk.DropDown, Gtk.Switch, Gtk.Scale)
NUDGE_PX = 20.0
_TAB, _SHIFT = Gdk.KEY_Tab, Gdk.ModifierType.SHIFT_MASK
"""Looked up once: every key press (a held drive key repeats 25 times a second) passes the first-Tab
check, and each lookup through PyGObject's module proxy costs more than the check itself."""
"""A pick mode's arrow key moves the picked point this far on screen (at least 100 mm)."""
NUDGE_MIN_MM = 100.0
TURN_DEG = 15.0
ROBOT_KEYS = 9
NUDGES = {"drive_forward": (0, 1), "drive_backward": (0, -1), "drive_left": (-1, 0), "drive_right": (1, 0)}
"""Drive key → screen direction (x right, y up) of a pick mode's nudge."""


def make_focusable(root: Gtk.Widget, *, skip: Iterable[Gtk.Widget] = ()) -> int:
    """Let every button-like widget under ``root`` take the focus (Tab); returns how many it changed."""
    skipped = tuple(skip)
    changed = 0
    for widget in descendants(root):
        if not isinstance(widget, FOCUSABLE) or widget.get_focusable():
            continue
        if any(s is widget or widget.is_ancestor(s) for s in skipped):
            continue
        widget.set_focusable(True)
        changed += 1
    return changed


class KeyboardNav:
    """See the module notes; the window's actions (``ui.actions``: ``open-menu``, ``goto-panel``,
    ``select-robot``, ``next-robot``, ``previous-robot``) run :meth:`open_menu`, :meth:`open_goto`,
    :meth:`select` and :meth:`step`; the window's keys ask :meth:`pick_key` first in a pick mode."""

    def __init__(self, window: MainWindow) -> None:
        self.window = window
        self.fleet: Fleet | None = None
        """Set by the fleet's binding (``fleet_bind``): the robots Alt+1…9 pick from."""
        self.robots_menu = Gio.Menu()
        self._robots_shown = False
        for button in (window.menu_button, window.fullscreen_bar.menu_button, window.goals_panel):
            button.set_focusable(True)  # a menu button's inner toggle takes the focus for it
            inner = button.get_first_child()
            if inner is not None:
                inner.set_focusable(True)
        self.refresh_focusable()
        # GTK gives a shown window's first focusable widget the focus; a teleoperation window starts
        # with none, so Return does nothing until the operator Tabs to a button.
        window.connect_after("map", lambda *_a: GLib.idle_add(self._no_first_focus))
        window.layers.connect("notify::visible", lambda *_a: self.refresh_focusable())
        tab = Gtk.EventControllerKey()  # the first Tab (from no focus) lands on STOP, the first button
        tab.set_propagation_phase(Gtk.PropagationPhase.CAPTURE)
        tab.connect("key-pressed", self._first_tab)
        window.add_controller(tab)

    def _first_tab(
        self, _c: Gtk.EventControllerKey, keyval: int, _code: int, state: Gdk.ModifierType
    ) -> bool:
        window = self.window
        if keyval != _TAB or state & _SHIFT or window.get_focus() is not None:
            return False
        bar = window.fullscreen_bar
        stop = bar.stop_button if bar.get_reveal_child() else window.stop_button
        window.set_focus_visible(True)
        return bool(stop.grab_focus())

    def _no_first_focus(self) -> bool:
        if not self.window.get_focus_visible():
            self.window.set_focus(None)
        return False

    def refresh_focusable(self) -> None:
        """Buttons made since (a layer's switch, the camera bar's) take the focus too."""
        w = self.window
        make_focusable(w, skip=(w.dpad, w.popup_stack))

    # -- what the window's actions run ---------------------------------------------------------
    def open_menu(self) -> None:
        """The menu of the bar on screen (the full-screen bar's while full screen)."""
        w = self.window
        bar = w.fullscreen_bar
        button = bar.menu_button if bar.get_reveal_child() else w.menu_button
        button.popup()

    def open_goto(self) -> None:
        panel = self.window.goals_panel
        if panel.get_visible():
            panel.popup()
        else:
            self.window.banners.tell(
                "notice:goto", "warning", _("Go to: this server does not navigate"), timeout=4.0
            )

    # -- the fleet -------------------------------------------------------------------------------
    def select(self, number: int) -> None:
        """Select the robot at place ``number`` (1-based) of the fleet's list."""
        fleet = self.fleet
        sessions = fleet.sessions.value if fleet is not None else ()
        if not 1 <= number <= len(sessions) or fleet is None:
            self.window.banners.tell(
                "notice:robot",
                "warning",
                _("There is no robot {number} in the list").format(number=number),
                timeout=3.0,
            )
            return
        fleet.select(sessions[number - 1])

    def step(self, by: int) -> None:
        fleet = self.fleet
        sessions = fleet.sessions.value if fleet is not None else ()
        if fleet is None or len(sessions) < 2:
            self.window.banners.tell(
                "notice:robot", "warning", _("Only one robot: nothing to switch to"), timeout=3.0
            )
            return
        selected = fleet.selected.value
        index = next((i for i, s in enumerate(sessions) if s is selected), 0)
        fleet.select(sessions[(index + by) % len(sessions)])

    def fleet_changed(self) -> None:
        """The robots of the fleet changed: the menu's Robots submenu lists them with their keys."""
        fleet = self.fleet
        sessions = fleet.sessions.value if fleet is not None else ()
        self.robots_menu.remove_all()
        for number, session in enumerate(sessions[:ROBOT_KEYS], start=1):
            self.robots_menu.append_item(menu_item(session.name, f"win.select-robot({number})"))
        self.robots_menu.append_item(menu_item(_("Next robot"), "win.next-robot"))
        self.robots_menu.append_item(menu_item(_("Previous robot"), "win.previous-robot"))
        many = len(sessions) > 1
        if many != self._robots_shown:
            self._robots_shown = many
            app_section = self.window.app_menu
            if many:
                app_section.insert_submenu(0, _("Robots"), self.robots_menu)
            else:
                app_section.remove(0)

    # -- a pick mode by keyboard ---------------------------------------------------------------
    def pick_key(self, name: str) -> bool:
        """In a pick mode, a drive key moves the picked point and Ctrl+Left/Right turn it; True if used."""
        picker = self.window.picker
        if not picker.active:
            return False
        stage = self.window.stage
        marker = picker.marker
        if marker is None:
            robot = stage.model.robot.value
            vp = stage.viewport
            x, y = (
                (robot.x, robot.y)
                if robot.numbers_at is not None
                else vp.to_world(vp.width / 2, vp.height / 2)
            )
            th = robot.th if picker.kind is MarkerKind.LOCALIZE else None
            marker = Marker(picker.kind, x, y, th)
        step = max(NUDGE_PX / max(stage.viewport.scale, 1e-9), NUDGE_MIN_MM)
        if name in NUDGES:
            dx, dy = NUDGES[name]
            marker = Marker(marker.kind, marker.x + dx * step, marker.y + dy * step, marker.th)
        elif name in ("ptz_left", "ptz_right"):
            th = stage.model.robot.value.th if marker.th is None else marker.th  # from the robot's heading
            th = math.remainder(th + (TURN_DEG if name == "ptz_left" else -TURN_DEG), 360.0)
            marker = Marker(marker.kind, marker.x, marker.y, th)
        else:
            return False
        picker.set_marker(marker)
        self.window.pose_bar.go_button.grab_focus()  # Return confirms
        return True

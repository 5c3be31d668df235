"""Landscape ⇄ portrait phone layout, chosen by the window's width. The window keeps composing.

libadwaita 1.2 (Debian 12) has no breakpoints, so the map stage's ``resize`` is the
signal, and the window's own width decides (split view and the fleet's robot list make
the map narrower, not the window): under :data:`NARROW` px the window is a phone —

* the status toolbar gives way to the one-line :class:`StatusStrip`;
* the touch D-pad is shown, centred at the bottom above the zoom buttons, where a
  thumb rests (the operator's own D-pad choice is restored when it widens again),
  and the server's popup cards move up above it;
* the header bar sheds what a phone does not need so that STOP, Connect, the menu,
  the camera and Go to still fit 360 px: the title (the strip says the state), the
  window's minimise/maximise/close buttons (a phone's shell closes apps; Quit is in
  the menu), the Connect buttons' fixed minimum width and 20 px of STOP's (still
  the first and the only red button); the full-screen bar sheds its status line and leave button
  (the menu leaves full screen) and the camera head's position takes a line above its buttons;

and at :data:`NARROW` or more everything is exactly as the landscape window
always was. Switching happens in an idle callback, never inside a size
allocation. A window opened on a screen narrower than :data:`NARROW` (a
phone) starts maximised at that screen's size instead of 800×480, and keeps
the phone layout on that screen whatever its width (:meth:`PhoneLayout.wants_narrow`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Gdk", "4.0")
from gi.repository import Gdk, GLib, Gtk  # noqa: E402

from .status_strip import StatusStrip  # noqa: E402

MainWindow = Any
"""``ui.window.MainWindow``, which imports this module: named, not imported (no import cycle)."""

NARROW = 600
"""Widths under this (px) get the phone layout; 800×480 landscape is well above it."""
DPAD_ABOVE_OSD = 64
"""Bottom margin of the phone's D-pad: clear of the zoom row under it."""


def screen_size() -> tuple[int, int] | None:
    """The first monitor's size (logical px), or None when it cannot be known yet."""
    display = Gdk.Display.get_default()
    monitors = display.get_monitors() if display is not None else None
    if monitors is None or monitors.get_n_items() == 0:
        return None
    monitor = monitors.get_item(0)
    if not isinstance(monitor, Gdk.Monitor):
        return None
    geometry = monitor.get_geometry()
    return geometry.width, geometry.height


def fit_default_size(window: Gtk.Window, width: int, height: int, *, beside_map: bool = False) -> None:
    """``set_default_size``, but never larger than the screen: a window made for a laptop opens on a
    phone at the phone's size, and its rows wrap (``wrapping_row``) instead of running off it.

    ``beside_map``: a window used together with the map under it (the map editor's tools) takes at
    most half of a small screen — the upper half of a portrait one, the left half of a landscape one
    under 1280 px — so the map stays in sight; it scrolls for the rest."""
    screen = screen_size()
    if screen is not None:
        sw, sh = screen
        width, height = min(width, sw), min(height, sh)
        if beside_map and sh > sw:
            height = min(height, sh // 2)
        elif beside_map and sw < 1280:
            width = min(width, sw // 2)
    window.set_default_size(width, height)


def wrapping_row(at_least: int = 1, at_most: int = 4) -> Gtk.FlowBox:
    """Buttons side by side (at least ``at_least`` on a line) that wrap onto another line when the room
    is narrower than their words: a longer language or a phone never widens the window past its screen."""
    row = Gtk.FlowBox(selection_mode=Gtk.SelectionMode.NONE, column_spacing=6, row_spacing=6, hexpand=True)
    row.set_min_children_per_line(at_least)
    row.set_max_children_per_line(at_most)
    row.set_homogeneous(False)
    return row


def monitor_width(window: Gtk.Window) -> int | None:
    """The width (logical px) of the monitor ``window`` is on, or None before it has a surface."""
    surface, display = window.get_surface(), window.get_display()
    monitor = display.get_monitor_at_surface(surface) if surface is not None else None
    return monitor.get_geometry().width if monitor is not None else None


class PhoneLayout:
    """Owns the strip and the switch; ``on_change(narrow)`` is told after each switch."""

    def __init__(self, window: MainWindow) -> None:
        self.window = window
        self.narrow = False
        self.on_change: Callable[[bool], None] | None = None
        self.strip = StatusStrip(window.model, window.operator)
        revealer = window.toolbar_revealer
        parent = revealer.get_parent()
        assert isinstance(parent, Gtk.Box)
        parent.insert_child_after(self.strip, revealer)
        self._dpad_before: bool | None = None
        self._popups_margin = window.popup_stack.get_margin_bottom()
        self._idle = 0
        size = screen_size()
        if size is not None and size[0] < NARROW:
            window.set_default_size(*size)  # a phone: fill its screen (its shell maximises apps too)
            window.maximize()
            self.apply(True)  # before the first size is computed: the landscape header would not fit
        # The stage resizes whenever the window does (and when split view or the fleet list takes a
        # side of it): the trigger. The choice is by the *window's* width: a map made narrower by the
        # video or the robot list beside it is not a phone, and must keep the title bar's buttons.
        self._resize_handler = window.stage.connect("resize", lambda _s, _w, _h: self._queue())

    def wants_narrow(self) -> bool | None:
        """Phone layout or not, None while the window has no width yet.

        A screen narrower than :data:`NARROW` always gets the phone layout, whatever the window's
        width: the landscape layout needs 512 px, more than a phone's screen, so once chosen there (the
        window made wider for a moment) a window manager that honours minimum sizes could never make
        the window narrow enough to switch back, and it would overflow the screen."""
        width = self.window.get_width()
        if width <= 0:
            return None
        screen = monitor_width(self.window)
        return width < NARROW or (screen is not None and screen < NARROW)

    def _queue(self) -> None:
        narrow = self.wants_narrow()
        if narrow is not None and narrow != self.narrow and not self._idle:
            self._idle = GLib.idle_add(self._apply_idle)

    def _apply_idle(self) -> bool:
        self._idle = 0
        narrow = self.wants_narrow()
        if narrow is not None:
            self.apply(narrow)
        return False

    def apply(self, narrow: bool) -> None:
        if narrow == self.narrow:
            return
        self.narrow = narrow
        w = self.window
        w.toolbar_revealer.set_visible(not narrow)
        self.strip.set_visible(narrow)
        if narrow:
            self.strip.refresh()
        (w.add_css_class if narrow else w.remove_css_class)("phone")  # STOP a little narrower, still first
        header = w.get_titlebar()
        if isinstance(header, Gtk.HeaderBar):
            header.set_decoration_layout("" if narrow else None)
        title_box = w.title_label.get_parent()
        if title_box is not None:
            title_box.set_visible(not narrow)
        w.fullscreen_bar.set_compact(narrow)
        w.ptz.set_compact(narrow)
        for button in (w.connect_button, w.fullscreen_bar.connect_button):
            (button.remove_css_class if narrow else button.add_css_class)("connect-button")
        dpad = w.dpad
        if narrow:
            self._dpad_before = dpad.get_visible()
            self._popups_margin = w.popup_stack.get_margin_bottom()
            self._show_dpad(True)
            dpad.set_halign(Gtk.Align.CENTER)
            dpad.set_margin_bottom(DPAD_ABOVE_OSD)
            pad_height = dpad.measure(Gtk.Orientation.VERTICAL, -1)[1]
            w.popup_stack.set_margin_bottom(DPAD_ABOVE_OSD + pad_height + 8)  # server popups above the pad
        else:
            dpad.set_halign(Gtk.Align.START)
            dpad.set_margin_bottom(12)
            w.popup_stack.set_margin_bottom(self._popups_margin)
            self._show_dpad(bool(self._dpad_before))
        if self.on_change is not None:
            self.on_change(narrow)

    def _show_dpad(self, on: bool) -> None:
        action = self.window.lookup_action("dpad")
        state = action.get_state() if action is not None else None
        if action is not None and state is not None:
            if state.get_boolean() != on:
                action.activate(None)  # the window's own toggle: D-pad, camera inset corner, menu check
        else:
            self.window.dpad.set_visible(on)

    def close(self) -> None:
        if self._idle:
            GLib.source_remove(self._idle)
            self._idle = 0
        if self._resize_handler:
            self.window.stage.disconnect(self._resize_handler)
            self._resize_handler = 0
        self.strip.close()

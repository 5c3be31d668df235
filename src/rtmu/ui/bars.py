"""The window's bars: the header bar, and the slim bar that stands in for it in full screen.

GTK hides a window's title bar in full screen, and with it Connect/Disconnect,
the menu and every way out — a trap on a touch tablet without a keyboard. So in
full screen a slim bar with the same essentials (STOP, Connect/Disconnect, the
status line, the menu and "leave full screen") is revealed at the top edge, and the
header's own end buttons (Go to, Routes, the camera) move into it while it shows
(:meth:`FullscreenBar.show_for`): a widget has one parent, and one button of each is one
state to keep.

STOP comes first in both and is the only red button: it is how the operator
stops the robot without a keyboard, so it never hides.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
from gi.repository import Gio, Gtk, Pango  # noqa: E402

from ..base.i18n import _  # noqa: E402
from . import accessible  # noqa: E402


def stop_button(on_stop: Callable[[], None]) -> Gtk.Button:
    """A red STOP button (icon and word: readable at arm's length, not only by colour)."""
    box = Gtk.Box(spacing=6, halign=Gtk.Align.CENTER)
    box.append(Gtk.Image.new_from_icon_name("media-playback-stop-symbolic"))
    box.append(Gtk.Label(label=_("STOP")))
    button = Gtk.Button(child=box, tooltip_text=_("Stop the robot now (Space)"))
    button.add_css_class("destructive-action")
    button.add_css_class("stop-button")
    button.set_focusable(False)
    button.connect("clicked", lambda _b: on_stop())
    accessible.name(button, _("STOP"))  # GTK 4.8 does not name a button from a label inside a box
    return button


def connect_button(on_click: Callable[[], None]) -> Gtk.Button:
    """Connect ⇄ Disconnect: a plain button (the window sets its label from the connection phase)."""
    button = Gtk.Button(label=_("Connect"))
    button.add_css_class("connect-button")
    button.set_focusable(False)
    button.connect("clicked", lambda _b: on_click())
    return button


def menu_button(menu: Gio.MenuModel, *, built_when_opened: bool = False) -> Gtk.MenuButton:
    """The main menu's button. ``built_when_opened``: its ~200 widgets are made the first time it opens
    (the full-screen bar's, hidden until full screen: building it made every launch slower)."""
    button = Gtk.MenuButton(icon_name="open-menu-symbolic", tooltip_text=_("Menu"))
    button.set_focusable(False)
    # The menu button's own inner toggle would take the window's first focus and then wear a focus
    # ring after any key press; keys go to the capture-phase router, so nothing here needs focus.
    inner = button.get_first_child()
    if inner is not None:
        inner.set_focusable(False)
    if built_when_opened:
        button.set_create_popup_func(_build_menu, menu)
    else:
        button.set_menu_model(menu)
    accessible.name_menu_button(button, _("Main menu"))
    return button


def _build_menu(button: Gtk.MenuButton, menu: Gio.MenuModel) -> None:
    """GTK asks before the popup shows: the menu is made once, the first time."""
    if button.get_menu_model() is None:
        button.set_menu_model(menu)


def show_connection(button: Gtk.Button, connected_ish: bool) -> None:
    button.set_label(_("Disconnect") if connected_ish else _("Connect"))
    button.set_tooltip_text(
        _("Disconnect (Ctrl+D); stops the robot first") if connected_ish else _("Connect (Ctrl+O)")
    )


class HeaderBar(Gtk.HeaderBar):
    """STOP, Connect/Disconnect, the title over the status line; at the end the menu, then ``end``
    (the window's camera, Routes and Go to buttons)."""

    def __init__(
        self,
        *,
        on_stop: Callable[[], None],
        on_connect: Callable[[], None],
        menu: Gio.MenuModel,
        end: Sequence[Gtk.Widget] = (),
    ) -> None:
        super().__init__()
        # Safety: STOP is always on screen, first in the bar and the only red button in it.
        self.stop_button = stop_button(on_stop)
        self.pack_start(self.stop_button)
        self.connect_button = connect_button(on_connect)
        self.pack_start(self.connect_button)
        title_box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, valign=Gtk.Align.CENTER)
        title_box.add_css_class("title-box")
        self.title_label = Gtk.Label(label=_("RTMU"))
        self.title_label.add_css_class("title")
        self.title_label.set_ellipsize(Pango.EllipsizeMode.END)  # a 560 px window keeps its buttons
        self.subtitle_label = Gtk.Label(label="")
        self.subtitle_label.add_css_class("subtitle")
        self.subtitle_label.set_ellipsize(Pango.EllipsizeMode.END)
        self.subtitle_label.set_max_width_chars(48)
        title_box.append(self.title_label)
        title_box.append(self.subtitle_label)
        self.set_title_widget(title_box)
        self.menu_button = menu_button(menu)
        self.pack_end(self.menu_button)
        self.end = tuple(end)
        """Go to, Routes and the camera: lent to the full-screen bar while it shows."""
        for widget in self.end:
            self.pack_end(widget)

    def show_status(self, connected_ish: bool, status: str) -> None:
        """Connect ⇄ Disconnect and the status line (``notes.status_line``)."""
        show_connection(self.connect_button, connected_ish)
        self.subtitle_label.set_text(status)


class FullscreenBar(Gtk.Revealer):
    """STOP, Connect/Disconnect, the status line, the menu and "leave full screen", at the top edge."""

    def __init__(
        self,
        *,
        on_stop: Callable[[], None],
        on_connect: Callable[[], None],
        on_leave: Callable[[], None],
        menu: Gio.MenuModel,
    ) -> None:
        super().__init__(transition_type=Gtk.RevealerTransitionType.SLIDE_DOWN, transition_duration=120)
        box = Gtk.Box(spacing=6)
        box.add_css_class("fullscreen-bar")
        self.stop_button = stop_button(on_stop)
        self.connect_button = connect_button(on_connect)
        self.status_label = Gtk.Label(xalign=0.0, hexpand=True)
        self.status_label.add_css_class("subtitle")
        self.status_label.set_ellipsize(Pango.EllipsizeMode.END)
        self.status_label.set_use_markup(False)
        self.menu_button = menu_button(menu, built_when_opened=True)
        self.leave_button = Gtk.Button(
            icon_name="view-restore-symbolic", tooltip_text=_("Leave full screen (F11)")
        )
        self.leave_button.set_focusable(False)
        accessible.name(self.leave_button, _("Leave full screen"))
        self.leave_button.connect("clicked", lambda _b: on_leave())
        for child in (self.stop_button, self.connect_button, self.status_label, self.menu_button):
            box.append(child)
        box.append(self.leave_button)
        self.box = box
        self.borrowed: tuple[Gtk.Widget, ...] = ()
        """The header's end buttons while full screen shows this bar (module notes)."""
        self.set_child(box)
        self.set_reveal_child(False)

    def show_for(self, on: bool, header: HeaderBar) -> None:
        """Full screen on or off: reveal the bar, and move the header's end buttons here or back."""
        self.set_reveal_child(on)
        if on and not self.borrowed:
            self.borrowed = header.end
            for widget in self.borrowed:  # packed from the end: Go to ends up first, as in the header
                header.remove(widget)
                self.box.insert_child_after(widget, self.status_label)
        elif not on and self.borrowed:
            for widget in self.borrowed:
                self.box.remove(widget)
                header.pack_end(widget)
            self.borrowed = ()

    def set_compact(self, on: bool) -> None:
        """The phone layout: shed the status line (the strip says it) and the leave button (the menu's
        "Full screen" leaves), so STOP, Connect, Go to, the camera and the menu fit a 360 px screen."""
        self.status_label.set_visible(not on)
        self.leave_button.set_visible(not on)

    def show_status(self, connected_ish: bool, status: str) -> None:
        """As the header bar's, which it stands in for."""
        show_connection(self.connect_button, connected_ish)
        self.status_label.set_text(status)

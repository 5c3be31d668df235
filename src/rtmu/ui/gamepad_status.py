"""The connected gamepad and its dead-man, over the map: the operator sees what the pad can do now.

A small pill at the map's top right, shown only while a pad is connected: its
name (plain text: a device name is untrusted), then "LB: hold to drive",
"LB held: driving" (blue, like a held key) or "Release LB to drive again"
(amber: a stop happened while it was held, see ``rtmu.control.gamepad``).
"""

from __future__ import annotations

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
from gi.repository import Gtk, Pango  # noqa: E402

from ..base.i18n import N_, _  # noqa: E402
from ..control.gamepad import DeadMan, PadState  # noqa: E402

TEXT = {
    DeadMan.NO_PAD: "",
    DeadMan.RELEASED: N_("LB: hold to drive"),
    DeadMan.HELD: N_("LB held: stick drives"),
    DeadMan.LATCHED: N_("Release LB to drive again"),
}


class GamepadStatus(Gtk.Box):
    """See the module notes; :meth:`show_state` takes the mapping's :class:`PadState`."""

    def __init__(self) -> None:
        super().__init__(orientation=Gtk.Orientation.HORIZONTAL, spacing=6, visible=False)
        self.add_css_class("gamepad-status")
        self.set_halign(Gtk.Align.END)
        self.set_valign(Gtk.Align.START)
        self.set_margin_top(8)
        self.set_margin_end(8)
        self.set_can_target(False)
        self.append(Gtk.Image.new_from_icon_name("input-gaming-symbolic"))
        self.name_label = Gtk.Label(max_width_chars=18, ellipsize=Pango.EllipsizeMode.END)
        self.name_label.set_use_markup(False)
        self.state_label = Gtk.Label()
        self.state_label.add_css_class("gamepad-deadman")
        self.append(self.name_label)
        self.append(self.state_label)
        self.state = PadState()

    def show_state(self, state: PadState) -> None:
        self.state = state
        self.set_visible(state.deadman is not DeadMan.NO_PAD)
        self.name_label.set_text(state.name)
        self.state_label.set_text(_(TEXT[state.deadman]))
        for d in DeadMan:
            css = f"deadman-{d.name.lower()}"
            (self.add_css_class if d is state.deadman else self.remove_css_class)(css)

    @property
    def text(self) -> str:
        return f"{self.name_label.get_text()} · {self.state_label.get_text()}" if self.get_visible() else ""

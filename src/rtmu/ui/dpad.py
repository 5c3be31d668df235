"""A touch D-pad over the map: press and hold an arrow to drive, Stop in the middle.

Each arrow drives exactly while a finger (or the mouse button) is down on it:
a ``Gtk.GestureDrag`` starts on touch-down and ends on lift *or* cancel, so a
finger that slides a little keeps driving and one that is taken away by another
gesture stops. The pad shows the hold (``held`` style) and drops it on release,
so the operator sees that the robot was let go. Stop acts on touch-down.
"""

from __future__ import annotations

from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

from ..base.i18n import N_, _  # noqa: E402
from . import accessible  # noqa: E402

PADS = (
    ("drive_forward", "go-up-symbolic", 1, 0, N_("Forward (hold)")),
    ("drive_left", "go-previous-symbolic", 0, 1, N_("Turn left (hold)")),
    ("drive_right", "go-next-symbolic", 2, 1, N_("Turn right (hold)")),
    ("drive_backward", "go-down-symbolic", 1, 2, N_("Backward (hold)")),
)
PAD_PX = 64
COMPACT_PAD_PX = 48
"""A pad on a narrow map in its corner (``dpad_place``): still a finger's width (48 px), and Fit can
then show the map above the D-pad instead of under it."""


class DPad(Gtk.Grid):
    def __init__(
        self, *, hold: Callable[[str], None], release: Callable[[str], None], stop: Callable[[], None]
    ) -> None:
        super().__init__()
        self.add_css_class("dpad")
        self.set_row_spacing(6)
        self.set_column_spacing(6)
        self.set_halign(Gtk.Align.START)
        self.set_valign(Gtk.Align.END)
        self.set_margin_start(12)
        self.set_margin_bottom(12)
        self._hold = hold
        self._release = release
        self.pads: dict[str, Gtk.Widget] = {}
        self.held: set[str] = set()
        for name, icon, col, row, tip in PADS:
            pad = self._pad(Gtk.Image.new_from_icon_name(icon), _(tip))
            drag = Gtk.GestureDrag()
            drag.set_button(0)
            drag.connect("begin", self._begin, name)
            drag.connect("end", self._end, name)
            pad.add_controller(drag)
            self.attach(pad, col, row, 1, 1)
            self.pads[name] = pad
        stop_pad = self._pad(Gtk.Label(label=_("STOP")), _("Stop (Space)"))
        stop_pad.add_css_class("stop")
        click = Gtk.GestureClick()
        click.set_button(0)
        click.connect("pressed", lambda *_a: stop())
        stop_pad.add_controller(click)
        self.attach(stop_pad, 1, 1, 1, 1)
        self.pads["stop"] = stop_pad

    def set_pad_size(self, px: int) -> None:
        """Every pad ``px`` square (a change only when it differs: no relayout otherwise)."""
        for pad in self.pads.values():
            if pad.get_size_request() != (px, px):
                pad.set_size_request(px, px)

    @staticmethod
    def _pad(child: Gtk.Widget, tooltip: str) -> Gtk.Widget:
        box = Gtk.Box(accessible_role=Gtk.AccessibleRole.BUTTON)  # a pad is a button to a screen reader
        box.add_css_class("dpad-button")
        box.set_size_request(PAD_PX, PAD_PX)
        child.set_hexpand(True)
        child.set_halign(Gtk.Align.CENTER)
        child.set_valign(Gtk.Align.CENTER)
        if isinstance(child, Gtk.Image):
            child.set_pixel_size(28)
        box.append(child)
        box.set_tooltip_text(tooltip)
        box.set_can_target(True)
        accessible.name(box, accessible.spoken(tooltip))
        return box

    def _begin(self, gesture: Gtk.GestureDrag, _seq: object, name: str) -> None:
        gesture.set_state(Gtk.EventSequenceState.CLAIMED)
        if name in self.held:
            return
        self.held.add(name)
        self.pads[name].add_css_class("held")
        self._hold(name)

    def _end(self, _gesture: Gtk.GestureDrag, _seq: object, name: str) -> None:
        if name not in self.held:
            return
        self.held.discard(name)
        self.pads[name].remove_css_class("held")
        self._release(name)

    def release_all(self) -> None:
        for name in list(self.held):
            self._end(None, None, name)  # type: ignore[arg-type]

    def set_command_state(self, name: str, enabled: bool, reason: str, label: str) -> None:
        pad = self.pads.get("stop" if name == "stop" else name)
        if pad is None:
            return
        pad.set_sensitive(enabled)
        pad.set_tooltip_text(label if enabled else f"{label}: {reason}")
        if not enabled and name in self.held:
            self._end(None, None, name)  # type: ignore[arg-type]

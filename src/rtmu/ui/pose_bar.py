"""The one-step confirm of a pick mode: what was picked, in words, with Go (or Set here) and Cancel.

It sits over the bottom of the map while a pick mode is on (``pose_pick``) and says what to do
first ("click where the robot should go"), then what will be sent ("Go to 12.30, 4.50 m facing
90°"). Only its confirm button sends anything: the picked pose goes to ``confirm`` and the mode ends.
"""

from __future__ import annotations

from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
from gi.repository import Gtk, Pango  # noqa: E402

from ..base.i18n import N_, _  # noqa: E402
from ..base.units import coordinates  # noqa: E402
from .nav_draw import Marker, MarkerKind  # noqa: E402
from .notes import heading_text  # noqa: E402
from .pose_pick import PosePicker  # noqa: E402

HINTS = {
    MarkerKind.GOTO: N_("Click where the robot should go; drag for its heading"),
    MarkerKind.LOCALIZE: N_("Click where the robot is; drag the way it faces"),
}
CONFIRM = {MarkerKind.GOTO: N_("Go"), MarkerKind.LOCALIZE: N_("Set here")}


def pose_words(marker: Marker) -> str:
    """``Go to 12.30, 4.50 m facing 90°`` / ``Robot at 2.50, 6.00 m facing 0°``."""
    where = coordinates(marker.x, marker.y)
    facing = (
        _("any heading")
        if marker.th is None
        else _("facing {heading_text}").format(heading_text=heading_text(marker.th))
    )
    head = _("Go to") if marker.kind is MarkerKind.GOTO else _("Robot at")
    return f"{head} {where}, {facing}"


class PoseBar(Gtk.Box):
    """Shown only while ``picker`` is in a mode; ``confirm(marker)`` sends, then the mode ends."""

    def __init__(self, picker: PosePicker, confirm: Callable[[Marker], None]) -> None:
        super().__init__(spacing=8, halign=Gtk.Align.CENTER, valign=Gtk.Align.END, visible=False)
        self.add_css_class("pose-bar")
        self.set_margin_bottom(62)  # above the zoom buttons, as the map note
        self.set_margin_start(8)
        self.set_margin_end(8)
        self.picker = picker
        self._confirm = confirm
        self.label = Gtk.Label(xalign=0.0, max_width_chars=56)
        self.label.set_use_markup(False)
        self.label.set_ellipsize(Pango.EllipsizeMode.END)
        self.go_button = Gtk.Button(label=_("Go"))
        self.go_button.add_css_class("suggested-action")
        self.go_button.set_focusable(False)
        self.go_button.connect("clicked", lambda _b: self.confirm())
        self.cancel_button = Gtk.Button(label=_("Cancel"))
        self.cancel_button.set_focusable(False)
        self.cancel_button.set_tooltip_text(_("Leave this mode without sending anything (Esc)"))
        self.cancel_button.connect("clicked", lambda _b: picker.cancel())
        for child in (self.label, self.go_button, self.cancel_button):
            self.append(child)
        self.update()

    def update(self) -> None:
        """Follow the picker (its ``changed`` hook calls this)."""
        kind, marker = self.picker.kind, self.picker.marker
        self.set_visible(kind is not None)
        if kind is None:
            return
        self.label.set_text(_(HINTS[kind]) if marker is None else pose_words(marker))
        self.go_button.set_label(_(CONFIRM[kind]))
        self.go_button.set_sensitive(marker is not None)

    def confirm(self) -> None:
        marker = self.picker.marker
        if marker is None:
            return
        self.picker.cancel()
        self._confirm(marker)

"""Turn-by-angle (T) and go-distance (G): a number, a few quick choices, Enter to go.

The thesis's operators asked for "turn the robot at a particular angle rather
than keep pressing the turn buttons". These dialogs call the controller's
``turn_by``/``move_distance`` (the server's ``turnByAngle``/``moveDist``); they
are only opened when the server offers the command.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gdk, GLib, Gtk  # noqa: E402

from ..base.i18n import _  # noqa: E402
from . import accessible  # noqa: E402


class AmountDialog(Gtk.Window):
    """One number with a unit and quick buttons; ``on_go(value)`` when confirmed."""

    def __init__(
        self,
        parent: Gtk.Window,
        *,
        title: str,
        prompt: str,
        unit: str,
        lower: float,
        upper: float,
        step: float,
        digits: int,
        initial: float,
        quick: Sequence[tuple[str, float]],
        on_go: Callable[[float], None],
    ) -> None:
        super().__init__(title=title, modal=True, transient_for=parent)
        self.set_resizable(False)
        self._on_go = on_go
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=10)
        for side in ("top", "bottom", "start", "end"):
            getattr(box, f"set_margin_{side}")(16)
        box.append(Gtk.Label(label=prompt, xalign=0.0))
        row = Gtk.Box(spacing=8)
        adjustment = Gtk.Adjustment(value=initial, lower=lower, upper=upper, step_increment=step,
                                    page_increment=step * 10)  # fmt: skip
        self.spin = Gtk.SpinButton(adjustment=adjustment, digits=digits, numeric=True, hexpand=True)
        accessible.name(self.spin, prompt)
        row.append(self.spin)
        row.append(Gtk.Label(label=unit))
        box.append(row)
        quick_row = Gtk.Box(spacing=6, homogeneous=True)
        for label, value in quick:
            b = Gtk.Button.new_with_label(label)
            b.connect("clicked", lambda _b, v=value: self._go(v))
            quick_row.append(b)
        box.append(quick_row)
        buttons = Gtk.Box(spacing=8, halign=Gtk.Align.END)
        cancel = accessible.mnemonic_button(_("_Cancel"))
        cancel.connect("clicked", lambda _b: self.close())
        go = accessible.mnemonic_button(_("_Go"))
        go.add_css_class("suggested-action")
        go.connect("clicked", lambda _b: self._go(self.spin.get_value()))
        buttons.append(cancel)
        buttons.append(go)
        box.append(buttons)
        self.set_child(box)
        self.set_default_widget(go)
        keys = Gtk.EventControllerKey()
        keys.set_propagation_phase(Gtk.PropagationPhase.CAPTURE)  # Enter in the number field = Go
        keys.connect("key-pressed", self._key)
        self.add_controller(keys)
        self.connect("close-request", lambda _w: self._give_back(parent))

    @staticmethod
    def _give_back(parent: Gtk.Window) -> bool:
        """The keyboard goes back to the window (driving, Space) as the dialog closes; False: close."""

        def present() -> bool:
            parent.present()
            return False

        GLib.idle_add(present)
        return False

    def _key(self, _c: Gtk.EventControllerKey, keyval: int, _code: int, _state: object) -> bool:
        if keyval == Gdk.KEY_Escape:
            self.close()
            return True
        if keyval in (Gdk.KEY_Return, Gdk.KEY_KP_Enter, Gdk.KEY_ISO_Enter):
            self.spin.update()
            self._go(self.spin.get_value())
            return True
        return False

    def _go(self, value: float) -> None:
        self.spin.update()
        self.close()
        if value:
            self._on_go(float(value))


def turn_dialog(parent: Gtk.Window, on_go: Callable[[float], None]) -> AmountDialog:
    return AmountDialog(
        parent,
        title=_("Turn by an angle"),
        prompt=_("Turn on the spot (positive = left, counter-clockwise):"),
        unit="degrees",
        lower=-180,
        upper=180,
        step=5,
        digits=0,
        initial=90,
        quick=(
            (_("90° left"), 90.0),
            (_("90° right"), -90.0),
            (_("About turn"), 180.0),
            (_("45° left"), 45.0),
        ),
        on_go=on_go,
    )


def go_dialog(parent: Gtk.Window, on_go: Callable[[float], None]) -> AmountDialog:
    return AmountDialog(
        parent,
        title=_("Go a distance"),
        prompt=_("Drive straight (negative = backwards):"),
        unit="metres",
        lower=-5,
        upper=10,
        step=0.1,
        digits=2,
        initial=1.0,
        quick=(("0.5 m", 0.5), ("1 m", 1.0), ("2 m", 2.0), (_("0.5 m back"), -0.5)),
        on_go=lambda metres: on_go(metres * 1000.0),
    )

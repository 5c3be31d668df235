"""Which motion is happening, always said over the map: "Navigating (autonomous)" or held driving.

The server driving the robot by itself and the operator holding a key are different promises — one
stops when a key is let go, the other does not — so the window names the one in force in a pill at
the map's top left (teal for autonomy, blue for a held drive, nothing while the robot is left alone):
a bold title, then where to ("To Lab B"), then how far and how to end it ("12.4 m left · Space or
STOP cancels"). Short
lines keep it narrow, clear of the banners centred at the top, even at 800 px. The words are
``nav_text.motion_text``; ``held()`` asks what holds a drive now ("" none; the window's
timer calls :meth:`refresh`, so the pill follows key presses within a tick). While the link is lost
the pill gives way to the link banner, which then says the robot is on its own.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
from gi.repository import Gtk, Pango  # noqa: E402

from ..model.observables import Phase, RobotModel  # noqa: E402
from .nav_text import motion_text  # noqa: E402

KINDS = ("autonomous", "held")


class _Held(Protocol):
    """The controller's view of a held drive (``control.controller.Controller``)."""

    @property
    def held(self) -> frozenset[str]: ...

    @property
    def analog_active(self) -> bool: ...


def held_by(controller: _Held, dpad_held: bool) -> str:
    """What holds a live drive: ``dpad``, ``keys``, ``pad`` (the gamepad's dead-man); "" none."""
    if controller.held:
        return "dpad" if dpad_held else "keys"
    return "pad" if controller.analog_active else ""


class MotionIndicator(Gtk.Box):
    """See the module notes; ``kind`` is what is shown now (``autonomous``, ``held`` or "")."""

    def __init__(self, model: RobotModel, held: Callable[[], str]) -> None:
        super().__init__(orientation=Gtk.Orientation.VERTICAL, visible=False)
        self.set_halign(Gtk.Align.START)
        self.set_valign(Gtk.Align.START)
        self.add_css_class("motion")
        for side in ("top", "start", "end"):
            getattr(self, f"set_margin_{side}")(8)
        self.set_can_target(False)
        self.lines: list[Gtk.Label] = []
        for css, chars in (
            ("motion-title", 28),
            ("motion-detail", 28),
            ("motion-hint", 36),
            ("motion-note", 28),
        ):
            label = Gtk.Label(xalign=0.0, max_width_chars=chars)
            label.add_css_class(css)
            label.set_ellipsize(Pango.EllipsizeMode.END)
            label.set_use_markup(False)  # goal names are the server's text
            self.append(label)
            self.lines.append(label)
        self.model = model
        self.held = held
        self.kind = ""
        self.note = ""
        """A fact about the motion from outside it (``idle_inhibit``: the screen is kept on)."""
        self._unobserve = [
            model.navigation.observe(lambda _o, _n: self.refresh()),
            model.connection.observe(lambda _o, _n: self.refresh()),
        ]
        self.refresh()

    @property
    def text(self) -> str:
        """What it says, on one line ("" while hidden)."""
        return " · ".join(t for t in (label.get_text() for label in self.lines) if t)

    def close(self) -> None:
        for remove in self._unobserve:
            remove()
        self._unobserve = []

    def set_note(self, note: str) -> None:
        """The last line while the pill shows (empty: none)."""
        if note != self.note:
            self.note = note
            self.refresh()

    def refresh(self) -> None:
        link_up = self.model.connection.value.phase is Phase.CONNECTED
        by = self.held()
        kind, lines = motion_text(self.model.navigation.value, held=bool(by), link_up=link_up, by=by)
        lines = (*lines[:3], *([""] * (3 - len(lines[:3]))), self.note) if kind else lines
        for i, label in enumerate(self.lines):
            text = lines[i] if i < len(lines) else ""
            if text != label.get_text():
                label.set_text(text)
            label.set_visible(bool(text))
        if kind != self.kind:
            for k in KINDS:
                (self.add_css_class if k == kind else self.remove_css_class)(f"motion-{k}")
            self.kind = kind
        self.set_visible(bool(kind))

"""Two tiny drawn gauges for the status toolbar: a battery and Wi-Fi bars.

Each is a fixed-size ``Gtk.DrawingArea`` with a value and a state; a greyed
state (stale or not published) is drawn in grey, never in the live colours.
The level maths is pure (:func:`battery_fraction`, :func:`wifi_bars`).
"""

from __future__ import annotations

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

from ..base.i18n import _  # noqa: E402
from . import accessible  # noqa: E402

GREEN = (0.18, 0.62, 0.27)
AMBER = (0.90, 0.60, 0.0)
RED = (0.85, 0.11, 0.14)
GREY = (0.6, 0.6, 0.62)
FULL_V = 13.0
"""A charged 12 V lead-acid Pioneer pack; the server sends only low and shutdown levels."""


def battery_fraction(volts: float | None, shutdown: float | None, *, is_soc: bool = False) -> float:
    """0…1 for the gauge: percent when the server sends a state of charge, else volts above shutdown."""
    if volts is None:
        return 0.0
    if is_soc:
        return max(0.0, min(1.0, volts / 100.0))
    empty = shutdown if shutdown is not None else 11.0
    span = max(0.5, FULL_V - empty)
    return max(0.0, min(1.0, (volts - empty) / span))


def wifi_bars(quality: int | None, signal: int | None) -> int:
    """0…4 bars from the link quality in % (preferred) or the signal in dBm."""
    if quality is not None:
        q = max(0, min(100, quality))
        return 0 if q <= 0 else min(4, 1 + q // 25)
    if signal is not None:
        for bars, floor in ((4, -55), (3, -67), (2, -75), (1, -85)):
            if signal >= floor:
                return bars
        return 0
    return 0


class BatteryGauge(Gtk.DrawingArea):
    def __init__(self) -> None:
        super().__init__(accessible_role=Gtk.AccessibleRole.METER)
        self.set_content_width(30)
        self.set_content_height(14)
        self.set_valign(Gtk.Align.CENTER)
        self.fraction = 0.0
        self.state = "unknown"
        """``ok``, ``low`` (amber), ``critical`` (red), ``unknown`` or ``stale`` (grey)."""
        self.set_draw_func(self._draw)
        accessible.name(self, _("Battery level"))

    def set_level(self, fraction: float, state: str) -> None:
        if (fraction, state) != (self.fraction, self.state):
            self.fraction, self.state = fraction, state
            self.queue_draw()
            words = {
                "ok": _("ok"),
                "low": _("low"),
                "critical": _("at shutdown level"),
                "unknown": _("unknown"),
                "stale": _("stale"),
            }.get(state, state)
            accessible.value(
                self,
                round(fraction * 100),
                0,
                100,
                _("{percent} %, {state}").format(percent=round(fraction * 100), state=words),
            )

    def _draw(self, _a: Gtk.DrawingArea, ctx, width: int, height: int) -> None:
        colour = {"ok": GREEN, "low": AMBER, "critical": RED}.get(self.state, GREY)
        body_w = width - 4
        ctx.set_line_width(1.5)
        ctx.set_source_rgb(*GREY if self.state in ("unknown", "stale") else (0.25, 0.25, 0.27))
        ctx.rectangle(0.75, 0.75, body_w - 1.5, height - 1.5)
        ctx.stroke()
        ctx.rectangle(body_w, height * 0.3, 3, height * 0.4)
        ctx.fill()
        ctx.set_source_rgb(*colour)
        ctx.rectangle(2.5, 2.5, max(0.0, (body_w - 5) * self.fraction), height - 5)
        ctx.fill()


class WifiGauge(Gtk.DrawingArea):
    def __init__(self) -> None:
        super().__init__(accessible_role=Gtk.AccessibleRole.METER)
        self.set_content_width(22)
        self.set_content_height(16)
        self.set_valign(Gtk.Align.CENTER)
        self.bars = 0
        self.live = False
        self.set_draw_func(self._draw)
        accessible.name(self, _("Wi-Fi signal"))

    def set_bars(self, bars: int, live: bool) -> None:
        if (bars, live) != (self.bars, self.live):
            self.bars, self.live = bars, live
            self.queue_draw()
            accessible.value(
                self, bars, 0, 4, _("{bars} of 4 bars").format(bars=bars) if live else _("no signal reading")
            )

    def _draw(self, _a: Gtk.DrawingArea, ctx, width: int, height: int) -> None:
        bar_w = (width - 3 * 2) / 4
        for i in range(4):
            h = height * (i + 1) / 4
            x = i * (bar_w + 2)
            on = self.live and i < self.bars
            colour = (GREEN if self.bars >= 2 else AMBER if self.bars == 1 else RED) if on else GREY
            ctx.set_source_rgba(*colour, 1.0 if on else 0.45)
            ctx.rectangle(x, height - h, bar_w, h)
            ctx.fill()

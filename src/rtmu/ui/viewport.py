"""Where the map is on the screen: zoom, centre and the world ⇄ pixel transform (pure, no GTK).

World coordinates are the map's millimetres, x to the right and y **up**;
screen pixels have y down. At 100 % one pixel is 10 mm (what ``rtmu.model.observables``
calls zoom 1.0), so 400 % shows a 455 mm robot 182 px long and 10 % shows a
30 m office in 300 px.

The pixel offset of the world origin is rounded to whole pixels so the tile
cache (which renders the map in fixed pixel tiles at one scale) and the
overlays drawn per frame line up exactly, with no blur from half-pixel blits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..base.units import percent

PX_PER_MM_AT_100 = 0.1
"""Pixels per millimetre at zoom 1.0 (100 %)."""
ZOOM_MIN = 0.1
ZOOM_MAX = 4.0
ZOOM_STEPS: tuple[float, ...] = (
    0.1, 0.125, 0.15, 0.2, 0.25, 0.3, 0.4, 0.5, 0.6, 0.75, 1.0, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0,
)  # fmt: skip
"""Stops of the zoom control, Ctrl+plus/minus and the scroll wheel (10 %…400 %)."""
FIT_MIN = 0.005
""""Fit map" may go below 10 % for a building that does not fit at 10 % (a 270 m map needs ~2 %)."""
FIT_MARGIN_PX = 16


@dataclass(frozen=True, slots=True)
class Viewport:
    """The widget's size, the zoom, and the world point shown at the widget's centre."""

    width: int = 800
    height: int = 480
    zoom: float = 1.0
    cx: float = 0.0
    """World x (mm) at the centre of the widget."""
    cy: float = 0.0

    @property
    def scale(self) -> float:
        """Pixels per millimetre."""
        return self.zoom * PX_PER_MM_AT_100

    @property
    def origin(self) -> tuple[int, int]:
        """Screen position of world (0, 0), rounded: ``sx = x * scale + ox``, ``sy = -y * scale + oy``."""
        s = self.scale
        return round(self.width / 2 - self.cx * s), round(self.height / 2 + self.cy * s)

    def to_screen(self, x: float, y: float) -> tuple[float, float]:
        ox, oy = self.origin
        s = self.scale
        return x * s + ox, -y * s + oy

    def to_world(self, sx: float, sy: float) -> tuple[float, float]:
        ox, oy = self.origin
        s = self.scale
        return (sx - ox) / s, (oy - sy) / s

    def visible_world(self, margin_px: float = 0.0) -> tuple[float, float, float, float]:
        """(min_x, min_y, max_x, max_y) in mm of what the widget shows, grown by ``margin_px``."""
        x0, y1 = self.to_world(-margin_px, -margin_px)
        x1, y0 = self.to_world(self.width + margin_px, self.height + margin_px)
        return x0, y0, x1, y1

    def sized(self, width: int, height: int) -> Viewport:
        return replace(self, width=max(1, int(width)), height=max(1, int(height)))

    def centred(self, x: float, y: float) -> Viewport:
        return replace(self, cx=float(x), cy=float(y))

    def panned(self, dx_px: float, dy_px: float) -> Viewport:
        """Content moved by (dx, dy) pixels, as a drag does."""
        s = self.scale
        return replace(self, cx=self.cx - dx_px / s, cy=self.cy + dy_px / s)

    def zoomed(self, zoom: float, anchor: tuple[float, float] | None = None) -> Viewport:
        """New zoom keeping the world point under ``anchor`` (screen px; default the centre) in place."""
        zoom = clamp_zoom(zoom, allow_fit=True)
        if anchor is None:
            return replace(self, zoom=zoom)
        ax, ay = anchor
        wx, wy = self.to_world(ax, ay)
        s = zoom * PX_PER_MM_AT_100
        cx = wx - (ax - self.width / 2) / s
        cy = wy + (ay - self.height / 2) / s
        return replace(self, zoom=zoom, cx=cx, cy=cy)


def clamp_zoom(zoom: float, *, allow_fit: bool = False) -> float:
    low = FIT_MIN if allow_fit else ZOOM_MIN
    if not math.isfinite(zoom):
        return 1.0
    return min(ZOOM_MAX, max(low, zoom))


def step_zoom(zoom: float, steps: int) -> float:
    """The zoom ``steps`` stops away (positive = in); from an in-between zoom the next stop counts as one."""
    if steps > 0:
        bigger = [z for z in ZOOM_STEPS if z > zoom * 1.001]
        return bigger[min(steps, len(bigger)) - 1] if bigger else ZOOM_MAX
    if steps < 0:
        smaller = [z for z in ZOOM_STEPS if z < zoom * 0.999]
        return smaller[max(steps, -len(smaller))] if smaller else min(zoom, ZOOM_MIN)
    return zoom


def nearest_step(zoom: float) -> float:
    """The stop closest to ``zoom`` on a log scale (a pinch ends on a stop so tiles can be reused)."""
    return min(ZOOM_STEPS, key=lambda z: abs(math.log(z / zoom)))


FIT_ROOM_SHARE = 0.5
"""Fit keeps clear of an overlay only while the map stays at least this share of its plain fit."""
Insets = tuple[int, int, int, int]
"""Pixels kept clear at the (left, top, right, bottom) edges: an overlay's corner (the D-pad)."""


def fit_view(
    bounds: tuple[float, float, float, float],
    width: int,
    height: int,
    *,
    margin: int = FIT_MARGIN_PX,
    insets: Insets = (0, 0, 0, 0),
) -> Viewport:
    """The viewport showing all of ``bounds`` (min_x, min_y, max_x, max_y in mm), centred in what
    ``insets`` leave of the widget, ≤ 400 %."""
    x0, y0, x1, y1 = bounds
    left, top, right, bottom = insets
    w = max(1.0, width - left - right - 2 * margin)
    h = max(1.0, height - top - bottom - 2 * margin)
    span_x = max(x1 - x0, 1000.0)
    span_y = max(y1 - y0, 1000.0)
    zoom = min(w / span_x, h / span_y) / PX_PER_MM_AT_100
    zoom = clamp_zoom(zoom, allow_fit=True)
    view = Viewport(width, height, zoom, (x0 + x1) / 2, (y0 + y1) / 2)
    # The bounds' centre at the centre of the free rectangle, not of the widget.
    return view.panned((left - right) / 2, (top - bottom) / 2)


def best_fit(
    bounds: tuple[float, float, float, float],
    width: int,
    height: int,
    choices: tuple[Insets, ...],
    floor: tuple[Insets, ...] = (),
) -> Viewport:
    """Of the ways to keep clear of an overlay (``choices``: beside it, above it …), the fit that
    shows the map largest — unless even that shows it at less than :data:`FIT_ROOM_SHARE` of the
    plain fit (a split phone's small map under a big D-pad): then the plain fit, legible. The plain
    fit keeps clear of what ``floor`` names in any case (its best way: the small zoom row)."""
    plain = max(
        (fit_view(bounds, width, height, insets=i) for i in floor),
        key=lambda v: v.zoom,
        default=fit_view(bounds, width, height),
    )
    views = [fit_view(bounds, width, height, insets=i) for i in choices]
    best = max(views, key=lambda v: v.zoom, default=plain)
    return best if best.zoom >= FIT_ROOM_SHARE * plain.zoom else plain


def zoom_label(zoom: float) -> str:
    """``"60 %"``; below 10 % one decimal (``"2.4 %"``)."""
    return percent(zoom * 100)

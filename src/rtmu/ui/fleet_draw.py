"""The other robots of a fleet on the map, GTK-free: drawn by ``frame.draw_frame`` so pixel tests see them.

Each robot keeps one colour everywhere (its map marker, its trail, its row in the robot
list): :func:`fleet_colour` by its place in the fleet. Blue comes first, so robot 1 of a
fleet looks like the one robot of a single-robot window; none is red (STOP's colour) or
grey (a stale robot's). A robot whose pose is stale is drawn grey with a dashed outline,
as the selected robot is.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cairo
import numpy as np

from . import overlays
from .viewport import Viewport

RGB = tuple[float, float, float]

FLEET_RGB: tuple[RGB, ...] = (
    overlays.ROBOT_RGB,  # blue
    (0.93, 0.47, 0.04),  # orange
    (0.16, 0.63, 0.24),  # green
    (0.58, 0.25, 0.78),  # purple
    (0.05, 0.62, 0.66),  # teal
    (0.86, 0.16, 0.55),  # magenta
    (0.55, 0.38, 0.16),  # brown
    (0.45, 0.52, 0.05),  # olive
)
TRAIL_ALPHA = 0.45
TRAIL_STEP_PX = 2.0
"""A trail point within this many pixels of the one before is not stroked (20 trails per frame stay cheap)."""


def fleet_colour(index: int) -> RGB:
    """The colour of the fleet's ``index``-th robot (the palette repeats after eight)."""
    return FLEET_RGB[index % len(FLEET_RGB)]


@dataclass(frozen=True, slots=True)
class FleetMark:
    """One other robot as the map draws it."""

    x: float
    y: float
    th: float
    rgb: RGB
    stale: bool
    trail: Sequence[tuple[float, float]] | np.ndarray = ()
    """The trail in mm: points, or an (n, 2) array (the window hands a cached array)."""


def draw_fleet(ctx: cairo.Context, vp: Viewport, marks: Sequence[FleetMark], *, footprint: bool) -> None:
    """Every other robot's trail, then every body (so no trail is drawn over a robot)."""
    for mark in marks:
        _draw_trail(ctx, vp, mark.trail, mark.rgb)
    for mark in marks:
        overlays.draw_robot(
            ctx, vp, mark.x, mark.y, mark.th, stale=mark.stale, footprint=footprint, rgb=mark.rgb
        )


def screen_polyline(vp: Viewport, trail: Sequence[tuple[float, float]] | np.ndarray) -> np.ndarray:
    """``trail`` (mm) on screen, as an (n, 2) array without points that fall on the previous one."""
    if len(trail) < 2:
        return np.empty((0, 2))
    pts = np.asarray(trail, dtype=float)
    ox, oy = vp.origin
    xy = np.column_stack((pts[:, 0] * vp.scale + ox, -pts[:, 1] * vp.scale + oy))
    cells = np.floor(xy / TRAIL_STEP_PX)
    keep = np.ones(len(xy), dtype=bool)
    keep[1:] = np.any(cells[1:] != cells[:-1], axis=1)
    keep[-1] = True
    return xy[keep]


def _draw_trail(
    ctx: cairo.Context, vp: Viewport, trail: Sequence[tuple[float, float]] | np.ndarray, rgb: RGB
) -> None:
    xy = screen_polyline(vp, trail)
    if len(xy) < 2:
        return
    ctx.save()
    ctx.new_path()
    ctx.set_source_rgba(*rgb, TRAIL_ALPHA)
    ctx.set_line_width(3.0)
    ctx.set_line_join(cairo.LINE_JOIN_ROUND)
    ctx.set_line_cap(cairo.LINE_CAP_ROUND)
    ctx.move_to(*xy[0])
    for x, y in xy[1:].tolist():
        ctx.line_to(x, y)
    ctx.stroke()
    ctx.restore()

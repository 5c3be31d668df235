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
    trail: Sequence[tuple[float, float]] = ()


def draw_fleet(ctx: cairo.Context, vp: Viewport, marks: Sequence[FleetMark], *, footprint: bool) -> None:
    """Every other robot's trail, then every body (so no trail is drawn over a robot)."""
    for mark in marks:
        overlays.draw_trail(ctx, vp, mark.trail, (*mark.rgb, TRAIL_ALPHA))
    for mark in marks:
        overlays.draw_robot(
            ctx, vp, mark.x, mark.y, mark.th, stale=mark.stale, footprint=footprint, rgb=mark.rgb
        )

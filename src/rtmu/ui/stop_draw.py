"""The stopping distance at the current speed, drawn ahead of the robot while it moves (GTK-free).

A robot told to stop does not stand still at once: a P3-DX at 1.5 m/s rolls almost 4 m
(``control.motion_limits``). While the robot moves, :func:`draw_stop_reach` shades the strip its
body will sweep before it can be standing — from its front (its back when reversing) to where that
edge will be once stopped — in red, with a bar across the end and the distance in words. Drawn by
:func:`rtmu.ui.frame.draw_frame` under the robot, so a pixel test sees what the window shows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cairo

from ..base.i18n import _
from ..base.units import metres
from ..control.motion_limits import RobotLimits
from . import overlays
from .viewport import Viewport

FILL_RGBA = (0.80, 0.11, 0.16, 0.20)
EDGE_RGBA = (0.75, 0.08, 0.12, 0.95)
MIN_SPEED_MM_S = 30.0
"""Slower than this, nothing is drawn (creeping, noise in the reported speed)."""
MIN_WIDTH_PX = 8.0


@dataclass(frozen=True, slots=True)
class StopReach:
    """A moving robot (mm, degrees counter-clockwise, signed mm/s) and how far it goes once told to stop."""

    x: float
    y: float
    th: float
    speed: float
    distance: float
    """mm the robot's centre still travels (reaction and braking)."""

    @property
    def words(self) -> str:
        return _("stops in {distance}").format(distance=metres(self.distance))


def stop_reach(x: float, y: float, th: float, speed: float, limits: RobotLimits) -> StopReach | None:
    """The reach of a robot going ``speed`` mm/s, or None while it is (nearly) still."""
    if not math.isfinite(speed) or abs(speed) < MIN_SPEED_MM_S:
        return None
    return StopReach(x, y, th, speed, limits.stopping_distance(speed))


def reach_corners(reach: StopReach) -> list[tuple[float, float]]:
    """The swept strip in map mm: from the leading edge now to the leading edge stopped."""
    ahead = 1.0 if reach.speed > 0 else -1.0
    edge = overlays.ROBOT_FRONT_MM if ahead > 0 else overlays.ROBOT_REAR_MM
    near, far = ahead * edge, ahead * (edge + reach.distance)
    half = overlays.ROBOT_HALF_WIDTH_MM
    c, s = math.cos(math.radians(reach.th)), math.sin(math.radians(reach.th))

    def at(along: float, side: float) -> tuple[float, float]:
        return reach.x + along * c - side * s, reach.y + along * s + side * c

    return [at(near, half), at(far, half), at(far, -half), at(near, -half)]


def draw_stop_reach(ctx: cairo.Context, vp: Viewport, reach: StopReach) -> None:
    """The strip, its end bar and the distance ("stops in 3.8 m") beside the end."""
    corners = [vp.to_screen(*p) for p in reach_corners(reach)]
    near_mid = ((corners[0][0] + corners[3][0]) / 2, (corners[0][1] + corners[3][1]) / 2)
    far_mid = ((corners[1][0] + corners[2][0]) / 2, (corners[1][1] + corners[2][1]) / 2)
    width = math.dist(corners[1], corners[2])
    ctx.save()
    ctx.new_path()
    if width < MIN_WIDTH_PX:  # zoomed far out: a strip of a few pixels still shows
        ctx.move_to(*near_mid)
        ctx.line_to(*far_mid)
        ctx.set_source_rgba(*FILL_RGBA[:3], 0.55)
        ctx.set_line_width(MIN_WIDTH_PX)
        ctx.stroke()
    else:
        ctx.move_to(*corners[0])
        for point in corners[1:]:
            ctx.line_to(*point)
        ctx.close_path()
        ctx.set_source_rgba(*FILL_RGBA)
        ctx.fill()
    scale = max(1.0, MIN_WIDTH_PX / max(width, 1e-9))
    ux, uy = corners[1][0] - corners[2][0], corners[1][1] - corners[2][1]
    bx, by = far_mid[0] + ux * scale / 2, far_mid[1] + uy * scale / 2
    ex, ey = far_mid[0] - ux * scale / 2, far_mid[1] - uy * scale / 2
    ctx.move_to(bx, by)
    ctx.line_to(ex, ey)
    ctx.set_source_rgba(*EDGE_RGBA)
    ctx.set_line_width(3.0)
    ctx.set_line_cap(cairo.LINE_CAP_ROUND)
    ctx.stroke()
    ctx.select_font_face("Sans", cairo.FONT_SLANT_NORMAL, cairo.FONT_WEIGHT_BOLD)
    ctx.set_font_size(11.0)
    extents = ctx.text_extents(reach.words)
    tx, ty = far_mid[0] + 8, far_mid[1] - 8
    ctx.rectangle(tx - 3, ty - extents.height - 3, extents.x_advance + 6, extents.height + 6)
    ctx.set_source_rgba(1, 1, 1, 0.85)
    ctx.fill()
    ctx.move_to(tx, ty)
    ctx.set_source_rgba(*EDGE_RGBA)
    ctx.show_text(reach.words)
    ctx.restore()

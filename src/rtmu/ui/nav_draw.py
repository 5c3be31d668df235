"""Navigation on the map, GTK-free: the planned path, the goal being driven to, and a picked pose.

Drawn by :func:`rtmu.ui.frame.draw_frame` over the cairns and under the robot, so a frame rendered
without a window (the tests, the benchmark) shows them exactly as the window does. One colour, teal,
means "where the server is taking the robot" (path, highlighted goal, go-to target); a picked
position for the robot itself is drawn as a dashed robot outline, because that is what it sets.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum

import cairo

from . import overlays
from .viewport import Viewport

PATH_RGB = (0.0, 0.60, 0.62)
"""Teal: apart from the blue robot and trail, orange sonar and goals, magenta laser, black walls."""
PATH_WIDTH_PX = 4.0
GOAL_RING_PX = 15.0
TARGET_RING_PX = 11.0
ARROW_PX = 34.0
"""Length of the heading arrow of a picked pose (screen pixels, whatever the zoom)."""


class MarkerKind(Enum):
    """What a picked pose is for: a point to drive to, or where the robot really is."""

    GOTO = "goto"
    LOCALIZE = "localize"


@dataclass(frozen=True, slots=True)
class Marker:
    """A pose the operator is picking on the map (mm, degrees; ``th`` None = no heading chosen)."""

    kind: MarkerKind
    x: float
    y: float
    th: float | None = None


def draw_path(
    ctx: cairo.Context, vp: Viewport, start: tuple[float, float] | None, path: Sequence[tuple[int, int]]
) -> None:
    """The path still ahead: from the robot (``start``) through every corner to the goal."""
    if not path:
        return
    points = ([start] if start is not None else []) + [(float(x), float(y)) for x, y in path]
    ctx.save()
    ctx.new_path()
    ctx.set_line_join(cairo.LINE_JOIN_ROUND)
    ctx.set_line_cap(cairo.LINE_CAP_ROUND)
    for i, (x, y) in enumerate(points):
        sx, sy = vp.to_screen(x, y)
        if i == 0:
            ctx.move_to(sx, sy)
        else:
            ctx.line_to(sx, sy)
    ctx.set_source_rgba(1, 1, 1, 0.85)  # a halo keeps the line apart from walls it runs along
    ctx.set_line_width(PATH_WIDTH_PX + 3)
    ctx.stroke_preserve()
    ctx.set_source_rgb(*PATH_RGB)
    ctx.set_line_width(PATH_WIDTH_PX)
    ctx.stroke()
    ctx.restore()


def draw_goal_highlight(ctx: cairo.Context, vp: Viewport, x: float, y: float) -> None:
    """A ring round the cairn the robot is heading for."""
    sx, sy = vp.to_screen(x, y)
    ctx.save()
    ctx.new_path()
    ctx.arc(sx, sy, GOAL_RING_PX, 0, 2 * math.pi)
    ctx.set_source_rgba(1, 1, 1, 0.9)
    ctx.set_line_width(7.0)
    ctx.stroke_preserve()
    ctx.set_source_rgb(*PATH_RGB)
    ctx.set_line_width(4.0)
    ctx.stroke()
    ctx.restore()


def draw_marker(ctx: cairo.Context, vp: Viewport, marker: Marker) -> None:
    """A go-to target (ring, cross and heading arrow) or a robot placed by hand (dashed outline)."""
    sx, sy = vp.to_screen(marker.x, marker.y)
    if marker.kind is MarkerKind.LOCALIZE:
        _ghost_robot(ctx, vp, marker)
    else:
        ctx.save()
        ctx.new_path()
        ctx.arc(sx, sy, TARGET_RING_PX, 0, 2 * math.pi)
        ctx.set_source_rgba(1, 1, 1, 0.9)
        ctx.set_line_width(6.0)
        ctx.stroke_preserve()
        ctx.set_source_rgb(*PATH_RGB)
        ctx.set_line_width(3.0)
        ctx.stroke()
        for dx, dy in ((1, 0), (0, 1)):
            ctx.move_to(sx - dx * 5, sy - dy * 5)
            ctx.line_to(sx + dx * 5, sy + dy * 5)
        ctx.set_line_width(2.0)
        ctx.stroke()
        ctx.restore()
    if marker.th is not None:
        _arrow(ctx, sx, sy, marker.th)


def _arrow(ctx: cairo.Context, sx: float, sy: float, th_deg: float) -> None:
    th = math.radians(th_deg)
    dx, dy = math.cos(th), -math.sin(th)  # screen y is down
    tip = (sx + dx * ARROW_PX, sy + dy * ARROW_PX)
    ctx.save()
    ctx.new_path()
    ctx.move_to(sx + dx * TARGET_RING_PX, sy + dy * TARGET_RING_PX)
    ctx.line_to(*tip)
    ctx.set_source_rgb(*PATH_RGB)
    ctx.set_line_width(3.0)
    ctx.stroke()
    ctx.move_to(*tip)
    ctx.line_to(tip[0] - 10 * dx + 6 * dy, tip[1] - 10 * dy - 6 * dx)
    ctx.line_to(tip[0] - 10 * dx - 6 * dy, tip[1] - 10 * dy + 6 * dx)
    ctx.close_path()
    ctx.fill()
    ctx.restore()


def _ghost_robot(ctx: cairo.Context, vp: Viewport, marker: Marker) -> None:
    """The robot's footprint where the operator says it is: translucent, dashed, not the real robot."""
    sx, sy = vp.to_screen(marker.x, marker.y)
    k = max(1.0, overlays.ROBOT_MIN_PX / ((overlays.ROBOT_FRONT_MM + overlays.ROBOT_REAR_MM) * vp.scale))
    k *= vp.scale
    ctx.save()
    ctx.new_path()
    ctx.translate(sx, sy)
    ctx.rotate(-math.radians(marker.th or 0.0))
    front, rear = overlays.ROBOT_FRONT_MM * k, overlays.ROBOT_REAR_MM * k
    half = overlays.ROBOT_HALF_WIDTH_MM * k
    ctx.rectangle(-rear, -half, front + rear, 2 * half)
    ctx.set_source_rgba(*overlays.ROBOT_RGB, 0.35)
    ctx.fill_preserve()
    ctx.set_source_rgb(*overlays.OUTLINE_RGB)
    ctx.set_line_width(2.0)
    ctx.set_dash([5.0, 3.0])
    ctx.stroke()
    ctx.restore()

"""The server's drawings on the map, GTK-free: ARIA's shapes in the server's colours and sizes.

Drawn by :func:`rtmu.ui.frame.draw_frame`, so a frame rendered without a window (tests, the
benchmark) shows exactly what the window shows. Each :class:`~rtmu.values.state.DrawingLayer` is drawn
opaque in its primary colour, lowest layer first; layers below the robot's (50) go under it, the
rest (range devices start at 70) over it. Shapes, as ARIA's ``ArDrawingData`` defines them:

* ``polyDots`` — a filled circle ``size`` mm across on each point (lasers);
* ``polyArrows`` — an arrow ``size`` mm long whose tip is on the point, its tail towards the robot (sonar);
* ``polyLine`` — one line through the points, ``size`` px wide;
* ``polyPoints`` — a small dot on each point;
* ``polySegments`` — a segment from point 2i to point 2i+1, ``size`` px wide.

Sizes are kept within what stays readable and cheap on screen (a hostile ``size`` cannot paint
the whole map), points far outside the view are skipped, and a layer with a shape RTMU does not
know is not drawn (the Layers panel says so).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import cairo

from ..values.state import DrawingLayer
from .viewport import Viewport

ROBOT_LAYER = 50
"""ARIA draws the robot on layer 50: lower layers go under it, higher ones over it."""
DOT_PX = (3.0, 40.0)
"""Smallest and largest dot diameter on screen (an 80 mm dot at 10 % zoom stays visible)."""
ARROW_PX = (8.0, 60.0)
LINE_PX = (1.0, 8.0)
POINT_PX = 2.0
MARGIN_PX = 60.0


def _rgb(color: int) -> tuple[float, float, float]:
    """0xRRGGBB as cairo's 0…1 floats."""
    return ((color >> 16) & 0xFF) / 255.0, ((color >> 8) & 0xFF) / 255.0, (color & 0xFF) / 255.0


def _clamp(value: float, bounds: tuple[float, float]) -> float:
    return min(max(value, bounds[0]), bounds[1])


def draw_layers(
    ctx: cairo.Context,
    vp: Viewport,
    layers: Sequence[DrawingLayer],
    robot_xy: tuple[float, float] | None,
    *,
    above_robot: bool,
) -> None:
    """Draw the shown, drawable layers on one side of the robot's layer, in layer order."""
    for layer in layers:
        if not (layer.shown and layer.drawable and layer.points):
            continue
        if (layer.layer > ROBOT_LAYER) is not above_robot:
            continue
        draw_layer(ctx, vp, layer, robot_xy)


def draw_layer(
    ctx: cairo.Context, vp: Viewport, layer: DrawingLayer, robot_xy: tuple[float, float] | None
) -> None:
    c = layer.color
    ctx.save()
    ctx.new_path()
    ctx.set_source_rgb(*_rgb(c))
    (ox, oy), k = vp.origin, vp.scale  # Viewport.to_screen, once per layer rather than per point
    screen = [(x * k + ox, -y * k + oy) for x, y in layer.points]
    shape = layer.shape
    if shape == "polyDots":
        _stamped_dots(ctx, vp, screen, _clamp(layer.size * vp.scale, DOT_PX) / 2, c)
    elif shape == "polyPoints":
        _pixels(ctx, vp, screen)
    elif shape == "polyArrows":
        _arrows(ctx, vp, layer, screen, robot_xy)
    elif shape == "polyLine":
        _line(ctx, screen, _clamp(layer.size, LINE_PX), segments=False)
    elif shape == "polySegments":
        _line(ctx, screen, _clamp(layer.size, LINE_PX), segments=True)
    ctx.restore()


def _on_screen(vp: Viewport, sx: float, sy: float) -> bool:
    return -MARGIN_PX <= sx <= vp.width + MARGIN_PX and -MARGIN_PX <= sy <= vp.height + MARGIN_PX


def _dots(ctx: cairo.Context, vp: Viewport, screen: list[tuple[float, float]], radius: float) -> None:
    for sx, sy in screen:
        if _on_screen(vp, sx, sy):
            ctx.new_sub_path()
            ctx.arc(sx, sy, radius, 0, 2 * math.pi)
            ctx.close_path()
    ctx.fill()


_STAMPS: dict[tuple[int, int], cairo.ImageSurface] = {}
"""One small picture of a dot per (colour, radius in px): painting it is ~2× cheaper than an arc a point."""


def _stamp(color: int, radius: float) -> cairo.ImageSurface:
    key = (color, round(radius * 2))
    stamp = _STAMPS.get(key)
    if stamp is None:
        if len(_STAMPS) > 64:  # colours and sizes come from the server: keep the cache small
            _STAMPS.clear()
        side = 2 * math.ceil(radius) + 1  # odd: the dot's centre is the middle of one pixel
        stamp = cairo.ImageSurface(cairo.FORMAT_ARGB32, side, side)
        sc = cairo.Context(stamp)
        sc.set_source_rgb(*_rgb(color))
        sc.arc(side / 2, side / 2, radius, 0, 2 * math.pi)
        sc.fill()
        _STAMPS[key] = stamp
    return stamp


def _stamped_dots(
    ctx: cairo.Context, vp: Viewport, screen: list[tuple[float, float]], radius: float, color: int
) -> None:
    stamp = _stamp(color, radius)
    k = stamp.get_width() // 2
    x1, y1 = vp.width + MARGIN_PX, vp.height + MARGIN_PX  # _on_screen, inlined: a laser is 1000s of dots
    for sx, sy in screen:
        if -MARGIN_PX <= sx <= x1 and -MARGIN_PX <= sy <= y1:  # centred on the pixel the point rounds to
            ctx.set_source_surface(stamp, round(sx) - k, round(sy) - k)
            ctx.paint()


def _pixels(ctx: cairo.Context, vp: Viewport, screen: list[tuple[float, float]]) -> None:
    """Crisp squares on whole pixels: thousands of localization samples stay cheap and sharp."""
    for sx, sy in screen:
        if _on_screen(vp, sx, sy):
            ctx.rectangle(math.floor(sx), math.floor(sy), POINT_PX, POINT_PX)
    ctx.fill()


def _arrows(
    ctx: cairo.Context,
    vp: Viewport,
    layer: DrawingLayer,
    screen: list[tuple[float, float]],
    robot_xy: tuple[float, float] | None,
) -> None:
    if robot_xy is None:  # no robot to point at: the points alone
        _dots(ctx, vp, screen, DOT_PX[0])
        return
    rx, ry = vp.to_screen(*robot_xy)
    length = _clamp(layer.size * vp.scale, ARROW_PX)
    head = min(length * 0.4, 10.0)
    ctx.set_line_width(2.0)
    ctx.set_line_cap(cairo.LINE_CAP_ROUND)
    heads: list[tuple[float, float, float, float, float, float]] = []
    for sx, sy in screen:
        if not _on_screen(vp, sx, sy):
            continue
        dx, dy = rx - sx, ry - sy
        dist = math.hypot(dx, dy)
        if dist < 1e-6:
            continue
        ux, uy = dx / dist, dy / dist  # from the point towards the robot
        ctx.move_to(sx + ux * length, sy + uy * length)
        ctx.line_to(sx, sy)
        bx, by = sx + ux * head, sy + uy * head
        heads.append(
            (sx, sy, bx - uy * head * 0.5, by + ux * head * 0.5, bx + uy * head * 0.5, by - ux * head * 0.5)
        )
    ctx.stroke()
    for tx, ty, ax, ay, bx2, by2 in heads:
        ctx.move_to(tx, ty)
        ctx.line_to(ax, ay)
        ctx.line_to(bx2, by2)
        ctx.close_path()
    ctx.fill()


def _line(ctx: cairo.Context, screen: list[tuple[float, float]], width: float, *, segments: bool) -> None:
    if len(screen) < 2:
        return
    ctx.set_line_width(width)
    ctx.set_line_cap(cairo.LINE_CAP_ROUND)
    ctx.set_line_join(cairo.LINE_JOIN_ROUND)
    if segments:
        for i in range(0, len(screen) - 1, 2):
            ctx.move_to(*screen[i])
            ctx.line_to(*screen[i + 1])
    else:
        ctx.move_to(*screen[0])
        for p in screen[1:]:
            ctx.line_to(*p)
    ctx.stroke()

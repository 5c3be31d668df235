"""What is drawn over the static map every frame: grid, cairns, trail, sonar and the robot.

Plain cairo (plus PangoCairo for names) on a :class:`~rtmu.ui.viewport.Viewport`,
no widgets, so the benchmark draws exactly what the window draws. Everything is
culled to the visible rectangle; names from the server are laid out with
``Pango.Layout.set_text`` (plain text, never markup) and cached per string.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import NamedTuple

import cairo
import gi

gi.require_version("Pango", "1.0")
gi.require_version("PangoCairo", "1.0")
from gi.repository import Pango, PangoCairo  # noqa: E402

from ..base.i18n import _  # noqa: E402
from .viewport import Viewport  # noqa: E402

# A Pioneer 3-DX (ARIA's p3dx parameters): 511 mm long, 210 mm of it in front of the
# centre of rotation, 425 mm wide, 250 mm radius. The server does not send its size.
ROBOT_FRONT_MM = 210.0
ROBOT_REAR_MM = 301.0
ROBOT_HALF_WIDTH_MM = 212.5
ROBOT_RADIUS_MM = 250.0
ROBOT_MIN_PX = 16.0
"""Below this length the robot is drawn as a marker of this size, so it never vanishes (and is as big
as the Home marker it often stands on)."""

ROBOT_RGB = (0.11, 0.44, 0.85)
STALE_RGB = (0.60, 0.61, 0.64)
"""An opaque mid grey (with a dashed dark outline): old, yet never mistaken for a marker or a wall."""
OUTLINE_RGB = (0.05, 0.1, 0.2)
TRAIL_RGBA = (0.11, 0.44, 0.85, 0.45)
SONAR_RGB = (0.90, 0.38, 0.0)
LASER_RGB = (0.85, 0.05, 0.55)
"""Laser points: magenta, apart from the orange sonar and the map's black."""
LASER_DOT_PX = 3.0
HOME_RGB = (0.15, 0.60, 0.30)
GOAL_RGB = (0.85, 0.45, 0.0)
DOCK_RGB = (0.50, 0.30, 0.70)
FORBIDDEN_RGB = (0.85, 0.10, 0.10)
AREA_RGB = (0.85, 0.65, 0.0)
GRID_MINOR = (0.0, 0.0, 0.0, 0.07)
GRID_MAJOR = (0.0, 0.0, 0.0, 0.16)
LABEL_MAX_CHARS = 40


class LabelCache:
    """Pango layouts for names, made once per string (a frame only positions them)."""

    def __init__(self, font: str = "Sans 9") -> None:
        self._context = PangoCairo.FontMap.get_default().create_context()
        self._font = Pango.FontDescription.from_string(font)
        self._layouts: dict[str, Pango.Layout] = {}

    def layout(self, text: str) -> Pango.Layout:
        text = _printable(text)
        layout = self._layouts.get(text)
        if layout is None:
            if len(self._layouts) > 2000:
                self._layouts.clear()
            layout = Pango.Layout.new(self._context)
            layout.set_font_description(self._font)
            layout.set_text(text, -1)
            self._layouts[text] = layout
        return layout


def _printable(text: str) -> str:
    """One line, bounded length, no control characters (names come from the network)."""
    clean = "".join(ch if ch.isprintable() else " " for ch in text).strip()
    return clean if len(clean) <= LABEL_MAX_CHARS else clean[: LABEL_MAX_CHARS - 1] + "…"


# -- grid (no map) ----------------------------------------------------------------------------------


def grid_step_mm(scale: float, min_px: float = 28.0) -> float:
    """The smallest of 0.1, 0.2, 0.5, 1, 2, 5, 10 … m whose lines are at least ``min_px`` apart."""
    step = 100.0
    factors = (2.0, 2.5, 2.0)
    k = 0
    while step * scale < min_px:
        step *= factors[k % 3]
        k += 1
    return step


def draw_grid(ctx: cairo.Context, vp: Viewport) -> float:
    """A metric grid (major line every 5 steps); returns the minor step in mm for the legend."""
    step = grid_step_mm(vp.scale)
    x0, y0, x1, y1 = vp.visible_world()
    ctx.save()
    ctx.new_path()
    ctx.set_line_width(1.0)
    for major in (False, True):
        ctx.set_source_rgba(*(GRID_MAJOR if major else GRID_MINOR))
        every = step * 5 if major else step
        i = math.floor(x0 / every)
        while i * every <= x1:
            sx, _ = vp.to_screen(i * every, 0)
            ctx.move_to(round(sx) + 0.5, 0)
            ctx.line_to(round(sx) + 0.5, vp.height)
            i += 1
        j = math.floor(y0 / every)
        while j * every <= y1:
            _, sy = vp.to_screen(0, j * every)
            ctx.move_to(0, round(sy) + 0.5)
            ctx.line_to(vp.width, round(sy) + 0.5)
            j += 1
        ctx.stroke()
    ctx.restore()
    return step


def metres(mm: float) -> str:
    """``"1 m"``, ``"20 cm"``, ``"2.5 m"``."""
    if mm < 1000:
        return _("{value:g} cm").format(value=mm / 10)
    return f"{mm / 1000:g} m"


def draw_scale_note(ctx: cairo.Context, labels: LabelCache, text: str) -> None:
    """A small legend at the top left (e.g. the grid's step)."""
    layout = labels.layout(text)
    _ink, logical = layout.get_pixel_extents()
    ctx.save()
    ctx.new_path()
    ctx.set_source_rgba(1, 1, 1, 0.8)
    ctx.rectangle(6, 6, logical.width + 10, logical.height + 4)
    ctx.fill()
    ctx.set_source_rgba(0, 0, 0, 0.7)
    ctx.move_to(11, 8)
    PangoCairo.show_layout(ctx, layout)
    ctx.new_path()  # show_layout leaves the current point at the text: the next shape must not join it
    ctx.restore()


# -- cairns -----------------------------------------------------------------------------------------


Box = tuple[float, float, float, float]
"""x0, y0, x1, y1 on the screen."""


def draw_cairns(
    ctx: cairo.Context,
    vp: Viewport,
    objects: Sequence[object],
    labels: LabelCache,
    avoid: Box | None = None,
    names: list[Box] | None = None,
) -> list[tuple[str, Box]]:
    """Home, goals (with names), docks, forbidden lines and areas, other areas; off-screen ones skipped.

    A name that would sit under ``avoid`` (the robot, drawn later on top) is moved below it.
    Returns the names drawn and their boxes; ``names`` gets the box of every name placed, drawn or
    not (``map_layer`` tells from them whether the robot would move one).
    """
    wx0, wy0, wx1, wy1 = vp.visible_world(margin_px=120)
    pending: list[_Label] = []
    for obj in objects:
        kind = str(getattr(obj, "type", "")).lower()
        from_xy = getattr(obj, "from_xy", None)
        to_xy = getattr(obj, "to_xy", None)
        if from_xy is not None and to_xy is not None:
            xs = (from_xy[0], to_xy[0])
            ys = (from_xy[1], to_xy[1])
            outside = max(xs) < wx0 or min(xs) > wx1 or max(ys) < wy0 or min(ys) > wy1
            if outside and not getattr(obj, "th", 0.0):
                continue
            if kind.endswith("line"):
                _draw_forbidden_line(ctx, vp, from_xy, to_xy)
            else:
                _draw_area(ctx, vp, obj, from_xy, to_xy, pending, forbidden="forbidden" in kind)
            continue
        x, y = float(getattr(obj, "x", 0.0)), float(getattr(obj, "y", 0.0))
        if not (wx0 <= x <= wx1 and wy0 <= y <= wy1):
            continue
        sx, sy = vp.to_screen(x, y)
        name = str(getattr(obj, "name", ""))
        th = float(getattr(obj, "th", 0.0))
        if kind in ("robothome", "home"):
            _marker(ctx, sx, sy, HOME_RGB, "house")
            pending.append(_Label(0, name or _("Home"), sx, sy + 10, HOME_RGB))
        elif kind.startswith("goal"):
            _marker(ctx, sx, sy, GOAL_RGB, "flag")
            if kind == "goalwithheading":
                _heading_tick(ctx, sx, sy, th, GOAL_RGB)
            pending.append(_Label(1, name, sx, sy + 10, GOAL_RGB))
        elif kind.startswith("dock"):
            _marker(ctx, sx, sy, DOCK_RGB, "dock")
            pending.append(_Label(2, name or _("Dock"), sx, sy + 10, DOCK_RGB))
        else:
            _marker(ctx, sx, sy, AREA_RGB, "dot")
            if name:
                pending.append(_Label(4, name, sx, sy + 8, AREA_RGB))
    return _draw_labels(ctx, labels, pending, avoid, names)


def region_corners(
    obj: object, from_xy: tuple[float, float], to_xy: tuple[float, float]
) -> list[tuple[float, float]]:
    """The four corners of a rectangle cairn: the from/to box rotated by ``th`` about the map origin."""
    (fx, fy), (tx, ty) = from_xy, to_xy
    th = math.radians(float(getattr(obj, "th", 0.0)))
    c, s = math.cos(th), math.sin(th)
    return [(px * c - py * s, px * s + py * c) for px, py in ((fx, fy), (tx, fy), (tx, ty), (fx, ty))]


def _draw_area(
    ctx: cairo.Context,
    vp: Viewport,
    obj: object,
    from_xy: tuple[float, float],
    to_xy: tuple[float, float],
    pending: list[_Label],
    *,
    forbidden: bool,
) -> None:
    rgb = FORBIDDEN_RGB if forbidden else AREA_RGB
    corners = [vp.to_screen(x, y) for x, y in region_corners(obj, from_xy, to_xy)]
    ctx.save()
    ctx.new_path()
    ctx.move_to(*corners[0])
    for c in corners[1:]:
        ctx.line_to(*c)
    ctx.close_path()
    ctx.set_source_rgba(*rgb, 0.16 if forbidden else 0.12)
    ctx.fill_preserve()
    ctx.set_source_rgba(*rgb, 0.8)
    ctx.set_line_width(1.5)
    ctx.set_dash([6.0, 4.0] if forbidden else [2.0, 3.0])
    ctx.stroke()
    ctx.restore()
    name = str(getattr(obj, "name", ""))
    if name:
        cx = sum(c[0] for c in corners) / 4
        cy = sum(c[1] for c in corners) / 4
        pending.append(_Label(3, name, cx, cy - 6, rgb))


def _draw_forbidden_line(
    ctx: cairo.Context, vp: Viewport, from_xy: tuple[float, float], to_xy: tuple[float, float]
) -> None:
    ctx.save()
    ctx.new_path()
    ctx.set_source_rgba(*FORBIDDEN_RGB, 0.9)
    ctx.set_line_width(3.0)
    ctx.set_dash([8.0, 5.0])
    ctx.move_to(*vp.to_screen(*from_xy))
    ctx.line_to(*vp.to_screen(*to_xy))
    ctx.stroke()
    ctx.restore()


def _marker(ctx: cairo.Context, sx: float, sy: float, rgb: tuple[float, float, float], shape: str) -> None:
    ctx.save()
    ctx.new_path()
    ctx.translate(sx, sy)
    ctx.set_line_width(1.5)
    if shape == "house":
        ctx.move_to(0, -9)
        for px, py in ((8, -1), (6, -1), (6, 7), (-6, 7), (-6, -1), (-8, -1)):
            ctx.line_to(px, py)
        ctx.close_path()
    elif shape == "flag":
        ctx.move_to(-1, 8)
        ctx.line_to(-1, -9)
        ctx.line_to(9, -5)
        ctx.line_to(-1, -1)
        ctx.close_path()
    elif shape == "dock":
        ctx.rectangle(-7, -5, 14, 10)
    else:
        ctx.arc(0, 0, 4, 0, 2 * math.pi)
        ctx.close_path()
    ctx.set_source_rgb(*rgb)
    ctx.fill_preserve()
    ctx.set_source_rgba(1, 1, 1, 0.9)
    ctx.set_line_width(1.0)
    ctx.stroke()
    ctx.restore()


def _heading_tick(
    ctx: cairo.Context, sx: float, sy: float, th_deg: float, rgb: tuple[float, float, float]
) -> None:
    th = math.radians(th_deg)
    ctx.save()
    ctx.new_path()
    ctx.set_source_rgb(*rgb)
    ctx.set_line_width(2.0)
    ctx.move_to(sx, sy)
    ctx.line_to(sx + 16 * math.cos(th), sy - 16 * math.sin(th))
    ctx.stroke()
    ctx.restore()


class _Label(NamedTuple):
    priority: int
    """Lower wins a collision: home, goals, docks, areas, the rest."""
    text: str
    sx: float
    sy: float
    rgb: tuple[float, float, float]


def overlap(a: Box, b: Box) -> bool:
    """Two screen boxes (x0, y0, x1, y1) share some area."""
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _draw_labels(
    ctx: cairo.Context,
    labels: LabelCache,
    pending: list[_Label],
    avoid: Box | None = None,
    names: list[Box] | None = None,
) -> list[tuple[str, Box]]:
    """Names under their marks on a light halo; one that would overlap a more important one is left out."""
    taken: list[Box] = []
    drawn: list[tuple[str, Box]] = []
    for item in sorted(pending, key=lambda p: p.priority):
        if not item.text:
            continue
        layout = labels.layout(item.text)
        _ink, logical = layout.get_pixel_extents()
        w, h = logical.width, logical.height
        x, y = round(item.sx - w / 2), round(item.sy)
        box = (x - 3, y - 1, x + w + 3, y + h + 1)
        if names is not None:
            names.append(box)
        if avoid is not None and overlap(box, avoid):
            y = round(avoid[3]) + 2  # under the robot instead of hidden by it
            box = (x - 3, y - 1, x + w + 3, y + h + 1)
        if any(overlap(box, b) for b in taken):
            continue
        taken.append(box)
        drawn.append((item.text, box))
        ctx.save()
        ctx.new_path()
        ctx.set_source_rgba(1, 1, 1, 0.78)
        ctx.rectangle(box[0], box[1], box[2] - box[0], box[3] - box[1])
        ctx.fill()
        ctx.set_source_rgb(*(c * 0.75 for c in item.rgb))
        ctx.move_to(x, y)
        PangoCairo.show_layout(ctx, layout)
        ctx.new_path()
        ctx.restore()
    return drawn


# -- trail, sonar, robot ------------------------------------------------------------------------------


def draw_trail(
    ctx: cairo.Context,
    vp: Viewport,
    trail: Iterable[tuple[float, float]],
    rgba: tuple[float, float, float, float] = TRAIL_RGBA,
) -> None:
    points = [vp.to_screen(x, y) for x, y in trail]
    if len(points) < 2:
        return
    ctx.save()
    ctx.new_path()
    ctx.set_source_rgba(*rgba)
    ctx.set_line_width(3.0)
    ctx.set_line_join(cairo.LINE_JOIN_ROUND)
    ctx.set_line_cap(cairo.LINE_CAP_ROUND)
    ctx.move_to(*points[0])
    for p in points[1:]:
        ctx.line_to(*p)
    ctx.stroke()
    ctx.restore()


def draw_sonar(
    ctx: cairo.Context, vp: Viewport, robot_xy: tuple[float, float], readings: Iterable[tuple[int, int]]
) -> None:
    """Each reading as a dot on a faint ray from the robot."""
    rx, ry = vp.to_screen(*robot_xy)
    dots = [vp.to_screen(x, y) for x, y in readings]
    if not dots:
        return
    ctx.save()
    ctx.new_path()
    ctx.set_source_rgba(*SONAR_RGB, 0.22)
    ctx.set_line_width(1.0)
    for sx, sy in dots:
        ctx.move_to(rx, ry)
        ctx.line_to(sx, sy)
    ctx.stroke()
    ctx.set_source_rgba(*SONAR_RGB, 0.95)
    for sx, sy in dots:
        ctx.new_sub_path()  # each dot on its own: no line from the previous one
        ctx.arc(sx, sy, 3.0, 0, 2 * math.pi)
        ctx.close_path()
    ctx.fill()
    ctx.restore()


def draw_laser(ctx: cairo.Context, vp: Viewport, points: Iterable[tuple[int, int]]) -> None:
    """Each laser point as a small square: hundreds per scan, so no rays (they would hide the map)."""
    ctx.save()
    ctx.new_path()
    ctx.set_source_rgba(*LASER_RGB, 0.9)
    for x, y in points:
        sx, sy = vp.to_screen(x, y)
        ctx.rectangle(sx - LASER_DOT_PX / 2, sy - LASER_DOT_PX / 2, LASER_DOT_PX, LASER_DOT_PX)
    ctx.fill()
    ctx.restore()


def draw_robot(
    ctx: cairo.Context,
    vp: Viewport,
    x: float,
    y: float,
    th_deg: float,
    *,
    stale: bool,
    footprint: bool = True,
    rgb: tuple[float, float, float] = ROBOT_RGB,
) -> None:
    """The robot to scale (footprint, or a circle when there is no map) with a heading mark.

    A robot smaller than :data:`ROBOT_MIN_PX` on screen is drawn at that size so it stays findable;
    a white halo keeps it apart from walls and markers under it. Stale (no fresh pose): opaque grey
    with a dashed outline.
    """
    sx, sy = vp.to_screen(x, y)
    k = _robot_px_per_mm(vp)
    th = math.radians(th_deg)
    rgb = STALE_RGB if stale else rgb
    ctx.save()
    ctx.new_path()  # whatever an earlier helper left as the current point must not join the body
    ctx.translate(sx, sy)
    ctx.rotate(-th)  # screen y is down: a counter-clockwise heading turns the other way on screen
    if footprint:
        _rounded_rect(ctx, -ROBOT_REAR_MM * k, -ROBOT_HALF_WIDTH_MM * k, (ROBOT_FRONT_MM + ROBOT_REAR_MM) * k,
                      2 * ROBOT_HALF_WIDTH_MM * k, 60 * k)  # fmt: skip
    else:
        ctx.new_sub_path()
        ctx.arc(0, 0, ROBOT_RADIUS_MM * k, 0, 2 * math.pi)
        ctx.close_path()
    ctx.set_source_rgba(1, 1, 1, 0.9)  # halo
    ctx.set_line_width(5.0)
    ctx.stroke_preserve()
    ctx.set_source_rgba(*rgb, 1.0 if stale else 0.92)
    ctx.fill_preserve()
    ctx.set_source_rgba(*OUTLINE_RGB, 0.9)
    ctx.set_line_width(1.5)
    if stale:
        ctx.set_dash([3.0, 2.0])
    ctx.stroke()
    ctx.set_dash([])
    # Heading: a white arrow from the centre to the front.
    front = (ROBOT_FRONT_MM if footprint else ROBOT_RADIUS_MM) * k
    ctx.set_source_rgb(1, 1, 1)
    ctx.set_line_width(max(1.5, 25 * k))
    ctx.move_to(0, 0)
    ctx.line_to(front * 0.98, 0)
    ctx.stroke()
    tip = front * 0.98
    head = max(4.0, 90 * k)
    ctx.move_to(tip, 0)
    ctx.line_to(tip - head, -head * 0.6)
    ctx.line_to(tip - head, head * 0.6)
    ctx.close_path()
    ctx.fill()
    ctx.restore()


def _robot_px_per_mm(vp: Viewport) -> float:
    length_px = (ROBOT_FRONT_MM + ROBOT_REAR_MM) * vp.scale
    return max(1.0, ROBOT_MIN_PX / length_px) * vp.scale


def robot_box(vp: Viewport, x: float, y: float) -> Box:
    """The screen box the robot (with its halo) covers, whatever its heading."""
    sx, sy = vp.to_screen(x, y)
    reach = max(ROBOT_RADIUS_MM, math.hypot(ROBOT_REAR_MM, ROBOT_HALF_WIDTH_MM))
    r = reach * _robot_px_per_mm(vp) + 3.0
    return (sx - r, sy - r, sx + r, sy + r)


def _rounded_rect(ctx: cairo.Context, x: float, y: float, w: float, h: float, r: float) -> None:
    r = min(r, w / 2, h / 2)
    ctx.new_sub_path()
    ctx.arc(x + w - r, y + r, r, -math.pi / 2, 0)
    ctx.arc(x + w - r, y + h - r, r, 0, math.pi / 2)
    ctx.arc(x + r, y + h - r, r, math.pi / 2, math.pi)
    ctx.arc(x + r, y + r, r, math.pi, 3 * math.pi / 2)
    ctx.close_path()

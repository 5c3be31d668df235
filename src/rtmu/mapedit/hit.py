"""Which of a map's editable objects is under a point: the map editor's click and drag on the map.

World coordinates only (mm), so the rule is tested without a window: the map turns its pointer's
reach in pixels into millimetres at the current zoom. Goals and docks come first (a small target on
top of a large one), then forbidden lines, then forbidden areas — the smallest area holding the point,
since areas may nest. A rectangle is rotated by its heading about the map's origin, as ARIA draws it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from ..mapfile import MapObject
from .draft import DOCK, FORBIDDEN_AREA, FORBIDDEN_LINE, GOAL, GOAL_WITH_HEADING

POINT_KINDS = frozenset(k.lower() for k in (GOAL, GOAL_WITH_HEADING, DOCK))


def object_at(objects: Iterable[MapObject], x: float, y: float, reach: float) -> MapObject | None:
    """The object a press at (``x``, ``y``) means, within ``reach`` mm of it; None: the map itself."""
    points: list[tuple[float, MapObject]] = []
    lines: list[tuple[float, MapObject]] = []
    areas: list[tuple[float, MapObject]] = []
    for obj in objects:
        kind = obj.type.lower()
        if kind in POINT_KINDS:
            d = math.hypot(obj.x - x, obj.y - y)
            if d <= reach:
                points.append((d, obj))
        elif kind == FORBIDDEN_LINE.lower() and obj.from_xy is not None and obj.to_xy is not None:
            d = _to_segment(x, y, obj.from_xy, obj.to_xy)
            if d <= reach:
                lines.append((d, obj))
        elif kind == FORBIDDEN_AREA.lower() and obj.from_xy is not None and obj.to_xy is not None:
            size = _inside(x, y, obj, reach)
            if size is not None:
                areas.append((size, obj))
    for found in (points, lines, areas):
        if found:
            return min(found, key=lambda pair: pair[0])[1]
    return None


def _to_segment(x: float, y: float, a: tuple[float, float], b: tuple[float, float]) -> float:
    ax, ay = a
    dx, dy = b[0] - ax, b[1] - ay
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0.0 else max(0.0, min(1.0, ((x - ax) * dx + (y - ay) * dy) / length2))
    return math.hypot(x - (ax + t * dx), y - (ay + t * dy))


def _inside(x: float, y: float, area: MapObject, reach: float) -> float | None:
    """The area's size when the point is inside it (grown by ``reach``), else None."""
    assert area.from_xy is not None and area.to_xy is not None
    turn = math.radians(-area.th)
    rx = x * math.cos(turn) - y * math.sin(turn)
    ry = x * math.sin(turn) + y * math.cos(turn)
    (x0, y0), (x1, y1) = area.from_xy, area.to_xy
    lo_x, hi_x = min(x0, x1) - reach, max(x0, x1) + reach
    lo_y, hi_y = min(y0, y1) - reach, max(y0, y1) + reach
    if lo_x <= rx <= hi_x and lo_y <= ry <= hi_y:
        return abs(x1 - x0) * abs(y1 - y0)
    return None

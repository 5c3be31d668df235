"""The simulator's path planner: an occupancy grid of the map, inflated by the robot; shortest paths on it.

Walls (map lines and points) and the map's ``ForbiddenLine`` / ``ForbiddenArea`` cairns are rasterised
into one grid; every cell closer to them than the robot's radius plus a rasterisation margin is blocked,
so a path through free cells keeps the whole round robot clear (and never crosses a forbidden line or
enters a forbidden area). Cells near walls cost more, which keeps paths in the middle of corridors.
Shortest paths come from scikit-image's ``MCP_Geometric`` (Dijkstra with true diagonal lengths), then
line-of-sight shortcutting on the grid leaves only the corners. A grid is built once per map
(:class:`GridCache` keeps the last one); on very large maps a coarse grid finds the route first and the
fine grid is searched piece by piece along it, so a plan costs about the same on any map.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np
from skimage.draw import polygon as fill_polygon
from skimage.graph import MCP_Geometric
from skimage.morphology import isotropic_dilation

from rtmu.mapfile import MapObject

from . import p3dx

MIN_CELL_MM = 50.0
MAX_FINE_CELLS = 6_000_000
"""Beyond this the cells grow (a 1 M-point building of 160 m × 170 m plans on ~68 mm cells)."""
SINGLE_SEARCH_CELLS = 1_500_000
"""Grids up to this size are searched whole; bigger ones coarse-first, then piece by piece."""
COARSE_FACTOR = 4
PIECE_COARSE_CELLS = 60
"""Fine search windows follow the coarse route this many coarse cells at a time."""
WINDOW_MARGIN_MM = 1500.0
FOLLOW_TOLERANCE_MM = 40.0
NEAR_WALL_MM = 300.0
"""Cells with less than this much room beyond the robot's radius cost :data:`NEAR_WALL_COST` instead of 1."""
NEAR_WALL_COST = 3.0
START_SNAP_MM = 600.0
"""A start inside the blocked margin (the robot was driven close to a wall) moves to the nearest free cell."""


class NoPath(Exception):
    """No plan: the goal is blocked or unreachable, or the start is walled in. ``reason`` says which."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


@dataclass(frozen=True, slots=True)
class Plan:
    points: tuple[tuple[float, float], ...]
    """Map mm from the start to the goal: the corners of the smoothed path."""

    @property
    def length_mm(self) -> float:
        p = np.asarray(self.points, dtype=np.float64)
        return float(np.hypot(*np.diff(p, axis=0).T).sum()) if len(p) > 1 else 0.0


def forbidden_shapes(objects: Iterable[MapObject]) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """``ForbiddenLine`` segments (x1, y1, x2, y2) and ``ForbiddenArea`` corner polygons (4 × 2) of a map.

    An area's corners are ``from``/``to`` rotated by its heading about the map origin, as ARIA does.
    """
    lines: list[np.ndarray] = []
    areas: list[np.ndarray] = []
    for obj in objects:
        if obj.from_xy is None or obj.to_xy is None:
            continue
        kind = obj.type.lower()
        (x1, y1), (x2, y2) = obj.from_xy, obj.to_xy
        if kind == "forbiddenline":
            lines.append(np.array([x1, y1, x2, y2], dtype=np.float64))
        elif kind == "forbiddenarea":
            corners = np.array([[x1, y1], [x2, y1], [x2, y2], [x1, y2]], dtype=np.float64)
            a = math.radians(obj.th)
            rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
            areas.append(corners @ rot.T)
    return lines, areas


class PlanGrid:
    """One map's planning grid: ``blocked`` cells, step ``costs``, and searches over them."""

    def __init__(
        self,
        segments: np.ndarray,
        points: np.ndarray,
        objects: Sequence[MapObject] = (),
        *,
        radius_mm: float = p3dx.RADIUS_MM,
        cell_mm: float | None = None,
    ) -> None:
        seg = np.asarray(segments, dtype=np.float64).reshape(-1, 4)
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        lines, areas = forbidden_shapes(objects)
        walls = np.concatenate([seg, np.asarray(lines, dtype=np.float64).reshape(-1, 4)])
        corners = [seg[:, 0:2], seg[:, 2:4], pts, *areas]
        every = np.concatenate([c for c in corners if len(c)] or [np.zeros((1, 2))])
        lo = every.min(axis=0) - 2 * radius_mm
        hi = every.max(axis=0) + 2 * radius_mm
        area = float(np.prod(hi - lo))
        self.cell = float(cell_mm or max(MIN_CELL_MM, math.sqrt(area / MAX_FINE_CELLS)))
        self.origin = lo
        self.shape = (int((hi[0] - lo[0]) // self.cell) + 1, int((hi[1] - lo[1]) // self.cell) + 1)
        self.radius = float(radius_mm)
        self.margin = self.radius + math.sqrt(2.0) * self.cell + FOLLOW_TOLERANCE_MM
        """Blocked within this of a wall cell: the robot's radius, what rasterising can hide, and room for
        the follower to be a little off the line."""

        occupied = np.zeros(self.shape, dtype=bool)
        self._mark_points(occupied, pts)
        self._mark_segments(occupied, walls)
        for poly in areas:
            cx, cy = self._to_cell_float(poly[:, 0], poly[:, 1])
            rr, cc = fill_polygon(cx, cy, self.shape)
            occupied[rr, cc] = True
            self._mark_segments(occupied, np.hstack([poly, np.roll(poly, -1, axis=0)]))
        occupied[0, :] = occupied[-1, :] = occupied[:, 0] = occupied[:, -1] = True  # the unknown beyond
        self.blocked = isotropic_dilation(occupied, self.margin, spacing=self.cell)
        near = isotropic_dilation(occupied, self.margin + NEAR_WALL_MM, spacing=self.cell)
        self.costs = np.where(self.blocked, np.inf, np.where(near, NEAR_WALL_COST, 1.0))
        self._mcp: MCP_Geometric | None = None
        self._coarse: _Coarse | None = None

    def prepare(self) -> None:
        """Build what the first plan would otherwise build (the coarse grid of a big map)."""
        if self.costs.size > SINGLE_SEARCH_CELLS and self._coarse is None:
            self._coarse = _Coarse(self)

    # -- coordinates ----------------------------------------------------------
    def _to_cell_float(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return (x - self.origin[0]) / self.cell, (y - self.origin[1]) / self.cell

    def to_cell(self, x: float, y: float) -> tuple[int, int]:
        return (int((x - self.origin[0]) // self.cell), int((y - self.origin[1]) // self.cell))

    def to_mm(self, i: float, j: float) -> tuple[float, float]:
        """The centre of cell (i, j)."""
        return (float(self.origin[0] + (i + 0.5) * self.cell), float(self.origin[1] + (j + 0.5) * self.cell))

    def inside(self, i: int, j: int) -> bool:
        return 0 <= i < self.shape[0] and 0 <= j < self.shape[1]

    def is_free(self, x: float, y: float) -> bool:
        i, j = self.to_cell(x, y)
        return self.inside(i, j) and not self.blocked[i, j]

    # -- rasterising ------------------------------------------------------------
    def _mark_points(self, grid: np.ndarray, pts: np.ndarray) -> None:
        if not len(pts):
            return
        ix, iy = self._to_cell_float(pts[:, 0], pts[:, 1])
        ix, iy = ix.astype(np.int64), iy.astype(np.int64)
        ok = (ix >= 0) & (iy >= 0) & (ix < grid.shape[0]) & (iy < grid.shape[1])
        grid[ix[ok], iy[ok]] = True

    def _mark_segments(self, grid: np.ndarray, seg: np.ndarray) -> None:
        """Every cell a segment passes through (sampled at a third of a cell)."""
        if not len(seg):
            return
        length = np.hypot(seg[:, 2] - seg[:, 0], seg[:, 3] - seg[:, 1])
        n = np.maximum(np.ceil(length / (self.cell / 3.0)).astype(np.int64), 1) + 1
        owner = np.repeat(np.arange(len(seg)), n)
        first = np.repeat(np.cumsum(n) - n, n)
        t = (np.arange(owner.size) - first) / np.repeat(n - 1, n)
        s = seg[owner]
        self._mark_points(
            grid, np.column_stack([s[:, 0] + t * (s[:, 2] - s[:, 0]), s[:, 1] + t * (s[:, 3] - s[:, 1])])
        )

    # -- questions ----------------------------------------------------------------
    def line_of_sight(
        self, a: tuple[float, float], b: tuple[float, float], blocked: np.ndarray | None = None
    ) -> bool:
        """True when every cell the straight line A→B passes through is free."""
        grid = self.blocked if blocked is None else blocked
        n = int(math.hypot(b[0] - a[0], b[1] - a[1]) / (self.cell / 4.0)) + 2
        t = np.linspace(0.0, 1.0, n)
        ix = ((a[0] + (b[0] - a[0]) * t - self.origin[0]) // self.cell).astype(np.int64)
        iy = ((a[1] + (b[1] - a[1]) * t - self.origin[1]) // self.cell).astype(np.int64)
        if ix.min() < 0 or iy.min() < 0 or ix.max() >= self.shape[0] or iy.max() >= self.shape[1]:
            return False
        return not grid[ix, iy].any()

    def plan(
        self,
        start: tuple[float, float],
        goal: tuple[float, float],
        extra: np.ndarray | None = None,
        *,
        coarse_first: bool = True,
    ) -> Plan:
        """The shortest safe path from ``start`` to ``goal`` (map mm), smoothed; raises :class:`NoPath`.

        ``extra`` are obstacle points (map mm) seen since the map was made — the robot's sonar — that
        block the plan as walls do. ``coarse_first=False`` searches a big grid whole (for comparison).
        """
        costs, blocked = self.costs, self.blocked
        if extra is not None and len(extra):
            seen = np.zeros(self.shape, dtype=bool)
            self._mark_points(seen, np.asarray(extra, dtype=np.float64).reshape(-1, 2))
            grown = isotropic_dilation(seen, self.margin, spacing=self.cell)
            blocked = blocked | grown
            costs = np.where(grown, np.inf, costs)
        gi, gj = self.to_cell(*goal)
        if not self.inside(gi, gj) or blocked[gi, gj]:
            raise NoPath("goal is not clear of obstacles")
        si, sj = self._free_start(start, blocked)
        if (si, sj) == (gi, gj):
            return Plan((start, goal))
        if coarse_first and costs is self.costs and self.costs.size > SINGLE_SEARCH_CELLS:
            cells = self._coarse_first((si, sj), (gi, gj))
        else:
            cells = self._search(costs, (si, sj), (gi, gj), shared=costs is self.costs)
        return Plan(self._smooth(start, goal, cells, blocked))

    def _free_start(self, start: tuple[float, float], blocked: np.ndarray) -> tuple[int, int]:
        si, sj = self.to_cell(*start)
        if self.inside(si, sj) and not blocked[si, sj]:
            return si, sj
        r = int(START_SNAP_MM // self.cell) + 1
        i0, j0 = max(si - r, 0), max(sj - r, 0)
        window = blocked[i0 : si + r + 1, j0 : sj + r + 1]
        free = np.argwhere(~window)
        if not len(free):
            raise NoPath("the robot is boxed in")
        d = np.hypot(free[:, 0] + i0 - si, free[:, 1] + j0 - sj)
        k = int(d.argmin())
        return int(free[k, 0] + i0), int(free[k, 1] + j0)

    def _search(
        self, costs: np.ndarray, start: tuple[int, int], goal: tuple[int, int], *, shared: bool = False
    ) -> list[tuple[int, int]]:
        if shared:
            if self._mcp is None:
                self._mcp = MCP_Geometric(self.costs)
            mcp = self._mcp
        else:
            mcp = MCP_Geometric(costs)
        cumulative, _ = mcp.find_costs([start], [goal])
        if not np.isfinite(cumulative[goal]):
            raise NoPath("no way to the goal")
        return [(int(i), int(j)) for i, j in mcp.traceback(goal)]

    def _coarse_first(self, start: tuple[int, int], goal: tuple[int, int]) -> list[tuple[int, int]]:
        """Route on a coarse grid, then follow it with fine searches in windows along the route."""
        if self._coarse is None:
            self._coarse = _Coarse(self)
        coarse = self._coarse
        k = COARSE_FACTOR
        route = coarse.route((start[0] // k, start[1] // k), (goal[0] // k, goal[1] // k))
        if route is None:
            raise NoPath("no way to the goal")
        anchors = [coarse.anchor(c) for c in route[PIECE_COARSE_CELLS::PIECE_COARSE_CELLS]]
        checkpoints = [c for c in anchors if c is not None and c != goal]
        margin = int(WINDOW_MARGIN_MM // self.cell) + k
        cells: list[tuple[int, int]] = []
        here = start
        for target in [*checkpoints, goal]:
            piece = self._windowed(here, target, margin)
            if piece is None:  # the coarse route promised more than the fine grid has: search it all
                return self._search(self.costs, start, goal, shared=True)
            cells += piece if not cells else piece[1:]
            here = target
        return cells

    def _windowed(self, a: tuple[int, int], b: tuple[int, int], margin: int) -> list[tuple[int, int]] | None:
        i0, j0 = max(min(a[0], b[0]) - margin, 0), max(min(a[1], b[1]) - margin, 0)
        i1 = min(max(a[0], b[0]) + margin + 1, self.shape[0])
        j1 = min(max(a[1], b[1]) + margin + 1, self.shape[1])
        try:
            local = self._search(self.costs[i0:i1, j0:j1], (a[0] - i0, a[1] - j0), (b[0] - i0, b[1] - j0))
        except NoPath:
            return None
        return [(i + i0, j + j0) for i, j in local]

    def _smooth(
        self,
        start: tuple[float, float],
        goal: tuple[float, float],
        cells: list[tuple[int, int]],
        blocked: np.ndarray,
    ) -> tuple[tuple[float, float], ...]:
        """Keep only the corners: from each kept point, jump to the farthest cell still in plain sight."""
        pts = [self.to_mm(i, j) for i, j in cells]
        pts[-1] = (float(goal[0]), float(goal[1]))
        first = (float(start[0]), float(start[1]))
        if self.line_of_sight(first, pts[0], blocked):
            pts[0] = first
        else:
            pts.insert(0, first)
        out = [pts[0]]
        a, n = 0, len(pts)
        while a < n - 1:
            good, step = a + 1, 1
            while good + step < n and self.line_of_sight(pts[a], pts[good + step], blocked):
                good += step
                step *= 2
            lo, hi = good, min(good + step, n)  # answer in [good, hi): binary search for the farthest seen
            while hi - lo > 1:
                mid = (lo + hi) // 2
                if self.line_of_sight(pts[a], pts[mid], blocked):
                    lo = mid
                else:
                    hi = mid
            out.append(pts[lo])
            a = lo
        return tuple(out)


class _Coarse:
    """A grid ``COARSE_FACTOR`` times coarser: a cell is passable when any fine cell in it is free."""

    def __init__(self, fine: PlanGrid) -> None:
        k = COARSE_FACTOR
        self.fine = fine
        ni, nj = -(-fine.shape[0] // k), -(-fine.shape[1] // k)
        free = np.zeros((ni * k, nj * k), dtype=bool)
        free[: fine.shape[0], : fine.shape[1]] = ~fine.blocked
        blocks = free.reshape(ni, k, nj, k)
        self.passable: np.ndarray = np.asarray(blocks.any(axis=(1, 3)))
        self.mcp = MCP_Geometric(np.where(self.passable, 1.0, np.inf))

    def route(self, a: tuple[int, int], b: tuple[int, int]) -> list[tuple[int, int]] | None:
        if not (self.passable[a] and self.passable[b]):
            return None
        cumulative, _ = self.mcp.find_costs([a], [b])
        if not np.isfinite(cumulative[b]):
            return None
        return [(int(i), int(j)) for i, j in self.mcp.traceback(b)]

    def anchor(self, c: tuple[int, int]) -> tuple[int, int] | None:
        """A free fine cell of coarse cell ``c``, the one nearest its middle."""
        k = COARSE_FACTOR
        block = self.fine.blocked[c[0] * k : (c[0] + 1) * k, c[1] * k : (c[1] + 1) * k]
        free = np.argwhere(~block)
        if not len(free):
            return None
        d = np.hypot(free[:, 0] - (k - 1) / 2, free[:, 1] - (k - 1) / 2)
        i, j = free[int(d.argmin())]
        return (int(c[0] * k + i), int(c[1] * k + j))


class GridCache:
    """The last map's grid: built on first use, and again only when the map's key (its MD5) changes.

    Thread-safe, so a server can build a big map's grid on a worker thread before the first plan.
    """

    def __init__(self) -> None:
        self._key: object = None
        self._grid: PlanGrid | None = None
        self._lock = threading.Lock()
        self.builds = 0

    def get(self, key: object, build: Callable[[], PlanGrid]) -> PlanGrid:
        with self._lock:
            if self._grid is None or key != self._key:
                grid = build()
                grid.prepare()
                self._grid, self._key = grid, key
                self.builds += 1
            return self._grid

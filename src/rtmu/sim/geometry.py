"""The simulated world's obstacles and the two questions asked of them: how far along a ray, how near a point.

Line segments are tested exactly (vectorised over the segments near the
question). Map points — ARIA maps can carry hundreds of thousands — are
rasterised once into an occupancy grid and rays march through it, so their
cost does not grow with their number.
"""

from __future__ import annotations

import math

import numpy as np

MAX_GRID_CELLS = 24_000_000
"""Occupancy grids larger than this get coarser cells instead (a 1 M-point map stays affordable)."""


class Obstacles:
    """Walls (segments) and occupied cells (points) in map millimetres."""

    def __init__(
        self,
        segments: np.ndarray | None = None,
        points: np.ndarray | None = None,
        *,
        point_cell_mm: float = 40.0,
    ) -> None:
        seg = np.zeros((0, 4)) if segments is None else np.asarray(segments, dtype=np.float64).reshape(-1, 4)
        pts = np.zeros((0, 2)) if points is None else np.asarray(points, dtype=np.float64).reshape(-1, 2)
        self.segments = seg
        self._seg_lo = np.minimum(seg[:, 0:2], seg[:, 2:4])
        self._seg_hi = np.maximum(seg[:, 0:2], seg[:, 2:4])
        self.points = pts
        self._grid: np.ndarray | None = None
        self.cell = float(point_cell_mm)
        self.origin = np.zeros(2)
        if len(pts):
            self._build_grid(pts)

    # -- set-up -------------------------------------------------------------
    def _build_grid(self, pts: np.ndarray) -> None:
        lo = pts.min(axis=0) - 2 * self.cell
        hi = pts.max(axis=0) + 2 * self.cell
        span = hi - lo
        cells = (span[0] / self.cell) * (span[1] / self.cell)
        if cells > MAX_GRID_CELLS:
            self.cell *= math.sqrt(cells / MAX_GRID_CELLS)
        shape = (int(span[0] // self.cell) + 1, int(span[1] // self.cell) + 1)
        grid = np.zeros(shape, dtype=bool)
        idx = ((pts - lo) // self.cell).astype(np.int64)
        grid[idx[:, 0], idx[:, 1]] = True
        self._grid = grid
        self.origin = lo

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(min x, min y, max x, max y) of everything, or a 10 m square when empty."""
        parts = []
        if len(self.segments):
            parts.append(self._seg_lo.min(axis=0))
            parts.append(self._seg_hi.max(axis=0))
        if len(self.points):
            parts.append(self.points.min(axis=0))
            parts.append(self.points.max(axis=0))
        if not parts:
            return (-5000.0, -5000.0, 5000.0, 5000.0)
        allp = np.vstack(parts)
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))

    def segments_near(self, x: float, y: float, reach: float) -> np.ndarray:
        """Segments whose bounding box comes within ``reach`` of (x, y)."""
        if not len(self.segments):
            return self.segments
        lo, hi = self._seg_lo, self._seg_hi
        mask = (lo[:, 0] <= x + reach) & (hi[:, 0] >= x - reach) & (lo[:, 1] <= y + reach)
        mask &= hi[:, 1] >= y - reach
        return self.segments[mask]

    # -- rays ---------------------------------------------------------------
    def cast(
        self,
        ox: np.ndarray | float,
        oy: np.ndarray | float,
        angles: np.ndarray,
        max_range: float,
    ) -> np.ndarray:
        """Distance along each ray to the first obstacle (``inf`` if none within ``max_range``).

        ``ox``/``oy`` are scalars or arrays matching ``angles`` (radians).
        """
        angles = np.asarray(angles, dtype=np.float64)
        ox_a = np.broadcast_to(np.asarray(ox, dtype=np.float64), angles.shape)
        oy_a = np.broadcast_to(np.asarray(oy, dtype=np.float64), angles.shape)
        dx, dy = np.cos(angles), np.sin(angles)
        cx, cy = float(ox_a.mean()), float(oy_a.mean())
        spread = float(np.hypot(ox_a - cx, oy_a - cy).max()) if angles.size else 0.0
        dist = self._cast_segments(ox_a, oy_a, dx, dy, self.segments_near(cx, cy, max_range + spread))
        if self._grid is not None:
            dist = np.minimum(dist, self._cast_grid(ox_a, oy_a, dx, dy, max_range))
        dist[dist > max_range] = np.inf
        return dist

    @staticmethod
    def _cast_segments(
        ox: np.ndarray, oy: np.ndarray, dx: np.ndarray, dy: np.ndarray, seg: np.ndarray
    ) -> np.ndarray:
        out = np.full(dx.shape, np.inf)
        if not len(seg):
            return out
        x1, y1, x2, y2 = (seg[:, i][None, :] for i in range(4))
        ex, ey = x2 - x1, y2 - y1
        rx, ry = dx[:, None], dy[:, None]
        denom = rx * ey - ry * ex
        wx, wy = x1 - ox[:, None], y1 - oy[:, None]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (wx * ey - wy * ex) / denom
            u = (wx * ry - wy * rx) / denom
        hit = (np.abs(denom) > 1e-12) & (t >= 0) & (u >= 0) & (u <= 1)
        t = np.where(hit, t, np.inf)
        return t.min(axis=1)

    def _cast_grid(
        self, ox: np.ndarray, oy: np.ndarray, dx: np.ndarray, dy: np.ndarray, max_range: float
    ) -> np.ndarray:
        """March every ray through the grid in growing chunks; a ray leaves the march at its first hit.

        Most rays hit something within a few metres, so marching all of them to ``max_range`` at once
        (the old way) did mostly wasted work; no ray marches past the grid's far corner either.
        """
        grid = self._grid
        assert grid is not None
        step = self.cell * 0.5
        n = int(max_range // step) + 2
        lo = self.origin
        hi = lo + np.asarray(grid.shape, dtype=np.float64) * self.cell
        far = max(
            float(
                np.hypot(
                    np.maximum(np.abs(ox - lo[0]), np.abs(ox - hi[0])),
                    np.maximum(np.abs(oy - lo[1]), np.abs(oy - hi[1])),
                ).max()
            )
            if ox.size
            else 0.0,
            0.0,
        )
        n = min(n, int(far // step) + 2)
        out = np.full(dx.shape, np.inf)
        todo = np.arange(dx.size)
        start, chunk = 1, 64
        while todo.size and start <= n:
            stop = min(start + chunk, n + 1)
            s = np.arange(start, stop, dtype=np.float64) * step
            px = (ox[todo, None] + dx[todo, None] * s[None, :] - lo[0]) / self.cell
            py = (oy[todo, None] + dy[todo, None] * s[None, :] - lo[1]) / self.cell
            ix, iy = np.floor(px).astype(np.int64), np.floor(py).astype(np.int64)
            inside = (ix >= 0) & (iy >= 0) & (ix < grid.shape[0]) & (iy < grid.shape[1])
            occupied = np.zeros(ix.shape, dtype=bool)
            occupied[inside] = grid[ix[inside], iy[inside]]
            hit = occupied.any(axis=1)
            first = occupied.argmax(axis=1)
            # Report the near edge of the cell, not its centre: subtract half a step.
            out[todo[hit]] = s[first[hit]] - step * 0.5
            todo = todo[~hit]
            start, chunk = stop, chunk * 2
        return out

    # -- clearance ----------------------------------------------------------
    def clearance(self, x: float, y: float, radius: float) -> float:
        """Distance from (x, y) to the nearest obstacle, looking no further than ``radius`` (else ``inf``)."""
        best = math.inf
        seg = self.segments_near(x, y, radius)
        if len(seg):
            x1, y1, x2, y2 = seg[:, 0], seg[:, 1], seg[:, 2], seg[:, 3]
            ex, ey = x2 - x1, y2 - y1
            length2 = ex * ex + ey * ey
            with np.errstate(divide="ignore", invalid="ignore"):
                t = np.clip(((x - x1) * ex + (y - y1) * ey) / length2, 0.0, 1.0)
            t = np.where(length2 > 0, t, 0.0)
            d = np.hypot(x1 + t * ex - x, y1 + t * ey - y)
            best = float(d.min())
        if self._grid is not None:
            best = min(best, self._grid_clearance(x, y, radius))
        return best if best <= radius else math.inf

    def _grid_clearance(self, x: float, y: float, radius: float) -> float:
        grid = self._grid
        assert grid is not None
        c = self.cell
        i0 = max(int((x - radius - self.origin[0]) // c), 0)
        i1 = min(int((x + radius - self.origin[0]) // c) + 1, grid.shape[0])
        j0 = max(int((y - radius - self.origin[1]) // c), 0)
        j1 = min(int((y + radius - self.origin[1]) // c) + 1, grid.shape[1])
        if i0 >= i1 or j0 >= j1:
            return math.inf
        window = grid[i0:i1, j0:j1]
        if not window.any():
            return math.inf
        ii, jj = np.nonzero(window)
        # Nearest point of each occupied cell to (x, y).
        cx0 = self.origin[0] + (ii + i0) * c
        cy0 = self.origin[1] + (jj + j0) * c
        nx = np.clip(x, cx0, cx0 + c)
        ny = np.clip(y, cy0, cy0 + c)
        return float(np.hypot(nx - x, ny - y).min())

    def segment_crossings(self, ax: float, ay: float, bx: float, by: float) -> int:
        """How many walls the straight line from A to B crosses (for radio attenuation)."""
        count = 0
        reach = math.hypot(bx - ax, by - ay)
        seg = self.segments_near((ax + bx) / 2, (ay + by) / 2, reach / 2 + 1)
        if len(seg):
            x1, y1, x2, y2 = seg[:, 0], seg[:, 1], seg[:, 2], seg[:, 3]
            d1 = (bx - ax) * (y1 - ay) - (by - ay) * (x1 - ax)
            d2 = (bx - ax) * (y2 - ay) - (by - ay) * (x2 - ax)
            d3 = (x2 - x1) * (ay - y1) - (y2 - y1) * (ax - x1)
            d4 = (x2 - x1) * (by - y1) - (y2 - y1) * (bx - x1)
            count += int(np.count_nonzero((d1 * d2 < 0) & (d3 * d4 < 0)))
        if self._grid is not None and reach > 0:
            count += self._grid_crossings(ax, ay, bx, by, reach)
        return count

    def _grid_crossings(self, ax: float, ay: float, bx: float, by: float, reach: float) -> int:
        """Runs of occupied cells along A→B, each counted as one wall."""
        grid = self._grid
        assert grid is not None
        n = int(reach // (self.cell * 0.5)) + 1
        s = np.linspace(0.0, 1.0, n)
        ix = np.floor((ax + (bx - ax) * s - self.origin[0]) / self.cell).astype(np.int64)
        iy = np.floor((ay + (by - ay) * s - self.origin[1]) / self.cell).astype(np.int64)
        inside = (ix >= 0) & (iy >= 0) & (ix < grid.shape[0]) & (iy < grid.shape[1])
        occ = np.zeros(n, dtype=bool)
        occ[inside] = grid[ix[inside], iy[inside]]
        return int(np.count_nonzero(occ[1:] & ~occ[:-1]) + (1 if occ[0] else 0))

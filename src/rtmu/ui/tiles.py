"""The static map as pixels: 256 px tiles per zoom, rendered on a worker thread, kept in an LRU.

Why: stroking a million map points with cairo costs seconds per frame
(gtk4-notes.md: 2.7 s at 1 M), and the thesis's client avoided high zoom on big
maps for that reason. The map never changes while the robot moves, so it is
rasterised once per zoom into tiles and each frame only blits the visible tiles
(~1 ms) and draws the robot and overlays on top.

* :class:`MapIndex` bins the points by cell (sorted keys + ``searchsorted``) so a
  tile only touches its own points; segments are tested by bounding box.
* :func:`render_region` rasterises points with numpy (it releases the GIL, so
  the GTK thread keeps running) and strokes segments with cairo when a tile has
  few of them (antialiased walls) or samples them with numpy when it has many.
* :class:`TileCache` owns one worker thread. The view asks for the tiles it
  shows (:meth:`TileCache.visible`); missing ones are queued, nearest to the
  centre first, and drawn from a low-resolution overview until they arrive;
  ``on_ready`` (called on the worker thread: wrap it with ``GLib.idle_add``) asks
  for a redraw. Nothing here imports GTK.
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass
from typing import cast

import cairo
import numpy as np

from ..base.memory import give_back

TILE = 256
"""Tile edge in pixels."""
BACKGROUND_RGB = (0.961, 0.957, 0.949)
POINT_RGB = (0.36, 0.36, 0.40)
LINE_RGB = (0.11, 0.11, 0.13)
CAIRO_LINE_LIMIT = 4000
"""Segments per tile up to which cairo strokes them (antialiased); more are sampled with numpy."""
MAX_SAMPLES = 6_000_000
"""Cap on line samples per tile (a pathological map must not eat the memory)."""
OVERVIEW_MAX_PX = 1024
"""The overview's longer side: shown only until a view's tiles arrive (ms), sharper than any fitted
view of a window up to 1024 px wide; at 2048 px it held 6.5 MB of an office map for those moments."""
DEFAULT_MAX_BYTES = 96 * 1024 * 1024
GIVE_BACK_AFTER_S = 1.0
"""Idle this long after rendering, the worker gives the burst's freed memory (the map decode's and
the tiles' numpy temporaries) back to the system: not at once, so a launch's first frame never
waits on the C heap's lock while it is trimmed."""
TARGET_POINTS_PER_CELL = 64


def _pack(rgb: tuple[float, float, float]) -> int:
    r, g, b = (round(c * 255) for c in rgb)
    return (0xFF << 24) | (r << 16) | (g << 8) | b


BACKGROUND = _pack(BACKGROUND_RGB)
POINT = _pack(POINT_RGB)
LINE = _pack(LINE_RGB)


class MapIndex:
    """The map's points binned into square cells, and its segments with bounding boxes, for rect queries."""

    def __init__(self, points: np.ndarray, segments: np.ndarray) -> None:
        pts = np.asarray(points, dtype=np.int32).reshape(-1, 2)
        segs = np.asarray(segments, dtype=np.float64).reshape(-1, 4)
        self.num_points = len(pts)
        self.num_segments = len(segs)
        self.bounds = _bounds(pts, segs)
        if len(pts):
            lo = pts.min(axis=0).astype(np.int64)
            hi = pts.max(axis=0).astype(np.int64)
            area = float(max(1, hi[0] - lo[0])) * float(max(1, hi[1] - lo[1]))
            self.cell = max(500.0, math.sqrt(area * TARGET_POINTS_PER_CELL / len(pts)))
            self.grid_origin = (int(lo[0]), int(lo[1]))
            col = ((pts[:, 0] - lo[0]) // self.cell).astype(np.int64)
            row = ((pts[:, 1] - lo[1]) // self.cell).astype(np.int64)
            self.cols = int(col.max()) + 1
            self.rows = int(row.max()) + 1
            key = row * self.cols + col
            order = np.argsort(key, kind="stable")
            self._keys = key[order]
            self._points = pts[order]
        else:
            self.cell, self.grid_origin, self.cols, self.rows = 1000.0, (0, 0), 0, 0
            self._keys = np.zeros(0, dtype=np.int64)
            self._points = pts
        self._segs = segs
        self._seg_lo = np.minimum(segs[:, 0:2], segs[:, 2:4])
        self._seg_hi = np.maximum(segs[:, 0:2], segs[:, 2:4])

    def points_in(self, x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
        """Points (k, 2) int32 with x0 <= x <= x1 and y0 <= y <= y1."""
        if not self.cols:
            return self._points[:0]
        gx, gy = self.grid_origin
        c0 = max(0, math.floor((x0 - gx) / self.cell))
        c1 = min(self.cols - 1, math.floor((x1 - gx) / self.cell))
        r0 = max(0, math.floor((y0 - gy) / self.cell))
        r1 = min(self.rows - 1, math.floor((y1 - gy) / self.cell))
        if c0 > c1 or r0 > r1:
            return self._points[:0]
        rows = np.arange(r0, r1 + 1, dtype=np.int64) * self.cols
        starts = np.searchsorted(self._keys, rows + c0, side="left")
        ends = np.searchsorted(self._keys, rows + c1, side="right")
        chunks = [self._points[s:e] for s, e in zip(starts.tolist(), ends.tolist(), strict=True) if e > s]
        if not chunks:
            return self._points[:0]
        pts = np.concatenate(chunks) if len(chunks) > 1 else chunks[0]
        keep = (pts[:, 0] >= x0) & (pts[:, 0] <= x1) & (pts[:, 1] >= y0) & (pts[:, 1] <= y1)
        return pts[keep]

    def segments_in(self, x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
        """Segments (k, 4) float64 whose bounding box meets the rectangle."""
        if not self.num_segments:
            return self._segs
        lo, hi = self._seg_lo, self._seg_hi
        keep = (hi[:, 0] >= x0) & (lo[:, 0] <= x1) & (hi[:, 1] >= y0) & (lo[:, 1] <= y1)
        return self._segs[keep]


def _bounds(pts: np.ndarray, segs: np.ndarray) -> tuple[float, float, float, float] | None:
    parts = []
    if len(pts):
        parts.append((pts[:, 0].min(), pts[:, 1].min(), pts[:, 0].max(), pts[:, 1].max()))
    if len(segs):
        xs, ys = segs[:, 0::2], segs[:, 1::2]
        parts.append((xs.min(), ys.min(), xs.max(), ys.max()))
    if not parts:
        return None
    return (
        float(min(p[0] for p in parts)),
        float(min(p[1] for p in parts)),
        float(max(p[2] for p in parts)),
        float(max(p[3] for p in parts)),
    )


def dot_size(scale: float) -> int:
    """Pixels per map point: 1 when zoomed out, bigger when a point stands for a lot of screen."""
    return 1 if scale < 0.15 else 2 if scale < 0.3 else 3


def line_width(scale: float) -> float:
    return 1.3 if scale < 0.05 else 1.8 if scale < 0.2 else 2.5


def render_region(
    index: MapIndex, scale: float, gx0: int, gy0: int, width: int, height: int
) -> cairo.ImageSurface:
    """Rasterise the map pixels [gx0, gx0+width) × [gy0, gy0+height) at ``scale`` px/mm.

    Pixel (gx, gy) holds world x in [gx/scale, (gx+1)/scale) and y with
    ``-y * scale`` in [gy, gy+1): the same rounding as ``Viewport.to_screen``.
    """
    surface = cairo.ImageSurface(cairo.FORMAT_RGB24, width, height)
    stride = surface.get_stride() // 4
    surface.flush()
    buf = np.ndarray((height, stride), dtype=np.uint32, buffer=surface.get_data())
    buf[:] = BACKGROUND
    pad = 4.0 / scale
    wx0, wx1 = gx0 / scale - pad, (gx0 + width) / scale + pad
    wy0, wy1 = -(gy0 + height) / scale - pad, -gy0 / scale + pad
    pts = index.points_in(wx0, wy0, wx1, wy1)
    if len(pts):
        px = np.floor(pts[:, 0] * scale).astype(np.int64) - gx0
        py = np.floor(-pts[:, 1] * scale).astype(np.int64) - gy0
        _stamp(buf, px, py, dot_size(scale), POINT, width, height)
    segs = index.segments_in(wx0, wy0, wx1, wy1)
    if len(segs) > CAIRO_LINE_LIMIT:
        _sample_segments(buf, segs, scale, gx0, gy0, width, height)
        surface.mark_dirty()
    elif len(segs):
        surface.mark_dirty()
        ctx = cairo.Context(surface)
        ctx.translate(-gx0, -gy0)
        ctx.set_source_rgb(*LINE_RGB)
        ctx.set_line_width(line_width(scale))
        ctx.set_line_cap(cairo.LINE_CAP_ROUND)
        for x0, y0, x1, y1 in (segs * np.array([scale, -scale, scale, -scale])).tolist():
            ctx.move_to(x0, y0)
            ctx.line_to(x1, y1)
        ctx.stroke()
        surface.flush()
    else:
        surface.mark_dirty()
    return surface


def _stamp(buf: np.ndarray, px: np.ndarray, py: np.ndarray, size: int, colour: int, w: int, h: int) -> None:
    """Set ``size``×``size`` pixel blocks at (px, py), clipped to the buffer."""
    for dy in range(size):
        for dx in range(size):
            x = px + dx
            y = py + dy
            keep = (x >= 0) & (x < w) & (y >= 0) & (y < h)
            buf[y[keep], x[keep]] = colour


def _sample_segments(
    buf: np.ndarray, segs: np.ndarray, scale: float, gx0: int, gy0: int, width: int, height: int
) -> None:
    """Draw many segments by sampling each at one pixel steps (clipped to the region first)."""
    x0 = segs[:, 0] * scale - gx0
    y0 = -segs[:, 1] * scale - gy0
    dx = segs[:, 2] * scale - gx0 - x0
    dy = -segs[:, 3] * scale - gy0 - y0
    t0, t1 = _clip(x0, y0, dx, dy, -2.0, -2.0, width + 2.0, height + 2.0)
    keep = t1 >= t0
    x0, y0, dx, dy, t0, t1 = x0[keep], y0[keep], dx[keep], dy[keep], t0[keep], t1[keep]
    length = np.hypot(dx, dy) * (t1 - t0)
    n = np.ceil(length).astype(np.int64) + 1
    total = int(n.sum())
    if total > MAX_SAMPLES:
        n = np.maximum(2, (n * (MAX_SAMPLES / total)).astype(np.int64))
        total = int(n.sum())
    if total == 0:
        return
    seg = np.repeat(np.arange(len(n)), n)
    first = np.repeat(np.cumsum(n) - n, n)
    frac = (np.arange(total) - first) / np.maximum(n - 1, 1)[seg]
    t = t0[seg] + frac * (t1 - t0)[seg]
    px = np.floor(x0[seg] + t * dx[seg]).astype(np.int64)
    py = np.floor(y0[seg] + t * dy[seg]).astype(np.int64)
    _stamp(buf, px, py, 2 if scale >= 0.05 else 1, LINE, width, height)


def _clip(
    x0: np.ndarray,
    y0: np.ndarray,
    dx: np.ndarray,
    dy: np.ndarray,
    xmin: float,
    ymin: float,
    xmax: float,
    ymax: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Liang–Barsky: the parameter range [t0, t1] of each segment inside the box (t1 < t0: outside)."""
    t0 = np.zeros_like(x0)
    t1 = np.ones_like(x0)
    with np.errstate(divide="ignore", invalid="ignore"):
        for p, q in ((-dx, x0 - xmin), (dx, xmax - x0), (-dy, y0 - ymin), (dy, ymax - y0)):
            parallel = p == 0
            t1 = np.where(parallel & (q < 0), -1.0, t1)
            r = np.where(parallel, 0.0, q / np.where(parallel, 1.0, p))
            t0 = np.where(~parallel & (p < 0), np.maximum(t0, r), t0)
            t1 = np.where(~parallel & (p > 0), np.minimum(t1, r), t1)
    return t0, t1


# -- the cache and its worker --------------------------------------------------------------------


EMPTY = object()
"""Marker for a tile with nothing on it: the background already shows it."""


@dataclass(frozen=True, slots=True)
class Overview:
    """The whole map at a small scale, drawn (stretched) where a tile is not ready yet."""

    surface: cairo.ImageSurface
    scale: float
    gx0: int
    gy0: int


@dataclass(frozen=True, slots=True)
class TileSpot:
    """One visible tile: screen position and its surface (None = not ready, :data:`EMPTY` = blank)."""

    x: int
    y: int
    surface: object | None


class TileCache:
    """Tiles of the current map, rendered on one worker thread; call it (but ``on_ready``) from one thread.

    ``on_ready()`` is called on the worker thread after new tiles arrive (at most
    once per :meth:`visible` call, so a burst of tiles costs one redraw).
    """

    def __init__(self, on_ready: Callable[[], None], *, max_bytes: int = DEFAULT_MAX_BYTES) -> None:
        self.on_ready = on_ready
        self.max_bytes = max_bytes
        self._lock = threading.Condition()
        self._tiles: OrderedDict[tuple[int, float, int, int], object] = OrderedDict()
        self._bytes = 0
        self._generation = 0
        self._map_arrays: tuple[np.ndarray, np.ndarray] | None = None
        self._index: MapIndex | None = None
        self._overview: Overview | None = None
        self._overview_done = False
        self._wanted: list[tuple[float, int, int]] = []
        self._scale = 0.0
        """The scale the view last asked for: tiles of one scale are kept (a launch's first fit, made
        before the window had its size, left 3.75 MB of tiles no frame showed again)."""
        self._notified = False
        self._closed = False
        self._busy = False
        self.rendered = 0
        """Tiles rendered so far (tests and the benchmark read it)."""
        self._thread = threading.Thread(target=self._work, name="rtmu-tiles", daemon=True)
        self._thread.start()

    # -- UI side -----------------------------------------------------------------------------
    def set_map(self, points: np.ndarray | None, segments: np.ndarray | None) -> None:
        """A new map (or None): forget every tile; the index is built on the worker."""
        with self._lock:
            self._generation += 1
            self._tiles.clear()
            self._bytes = 0
            self._index = None
            self._overview = None
            self._overview_done = False
            self._wanted = []
            if points is None and segments is None:
                self._map_arrays = None
            else:
                self._map_arrays = (
                    np.zeros((0, 2), np.int32) if points is None else points,
                    np.zeros((0, 4), np.int32) if segments is None else segments,
                )
            self._lock.notify_all()

    @property
    def ready(self) -> bool:
        """The index is built (tiles can be rendered)."""
        with self._lock:
            return self._index is not None

    @property
    def generation(self) -> int:
        """Counts the maps set: a picture made of this map's tiles is stale once it changes."""
        with self._lock:
            return self._generation

    @property
    def bounds(self) -> tuple[float, float, float, float] | None:
        with self._lock:
            return None if self._index is None else self._index.bounds

    @property
    def overview(self) -> Overview | None:
        with self._lock:
            return self._overview

    def visible(self, scale: float, origin: tuple[int, int], width: int, height: int) -> list[TileSpot]:
        """The tiles covering a ``width``×``height`` widget; queues the missing ones (and a ring around)."""
        ox, oy = origin
        i0, i1 = math.floor(-ox / TILE), math.floor((width - 1 - ox) / TILE)
        j0, j1 = math.floor(-oy / TILE), math.floor((height - 1 - oy) / TILE)
        spots: list[TileSpot] = []
        wanted: list[tuple[float, int, int]] = []
        centre_i, centre_j = (-ox + width / 2) / TILE, (-oy + height / 2) / TILE
        with self._lock:
            self._notified = False
            gen = self._generation
            if scale != self._scale:  # a new zoom: the tiles of the old one go (re-rendered in ms)
                self._scale = scale
                for key in [k for k in self._tiles if k[1] != scale]:
                    if self._tiles.pop(key) is not EMPTY:
                        self._bytes -= TILE * TILE * 4
            for j in range(j0, j1 + 1):
                for i in range(i0, i1 + 1):
                    key = (gen, scale, i, j)
                    surface = self._tiles.get(key)
                    if surface is not None:
                        self._tiles.move_to_end(key)
                    else:
                        wanted.append((scale, i, j))
                    spots.append(TileSpot(i * TILE + ox, j * TILE + oy, surface))
            # Prefetch one ring around the view (follow mode pans into it next).
            for j in range(j0 - 1, j1 + 2):
                for i in range(i0 - 1, i1 + 2):
                    if (i0 <= i <= i1 and j0 <= j <= j1) or (gen, scale, i, j) in self._tiles:
                        continue
                    wanted.append((scale, i, j))
            wanted.sort(key=lambda w: (w[1] + 0.5 - centre_i) ** 2 + (w[2] + 0.5 - centre_j) ** 2)
            if wanted != self._wanted:
                self._wanted = wanted
                self._lock.notify_all()
        return spots

    def close(self) -> None:
        with self._lock:
            self._closed = True
            self._lock.notify_all()
        self._thread.join(2.0)

    def wait_idle(self, timeout: float = 10.0) -> bool:
        """Block until nothing is queued (benchmarks and tests only; never on the GTK thread)."""
        with self._lock:
            return self._lock.wait_for(lambda: not self._has_work() and not self._busy, timeout)

    # -- worker ------------------------------------------------------------------------------
    def _work(self) -> None:
        trim_due = False
        while True:
            with self._lock:
                woken = self._lock.wait_for(
                    lambda: self._closed or self._has_work(), GIVE_BACK_AFTER_S if trim_due else None
                )
                if not woken:  # idle a while after a burst: its freed memory goes back to the system
                    trim_due = False
                    self._lock.release()  # not held while the C heap is trimmed (a few ms)
                    try:
                        give_back()
                    finally:
                        self._lock.acquire()
                    continue
                if self._closed:
                    return
                gen = self._generation
                if self._index is None:
                    job: tuple[str, object] = ("index", self._map_arrays)
                elif not self._overview_done:
                    job = ("overview", self._index)
                else:
                    job = ("tile", (self._index, self._wanted.pop(0)))
                self._busy = True
            try:
                self._run(gen, job)
            except Exception:  # a bad map must not kill the worker; the view keeps its overview/grid
                import logging

                logging.getLogger(__name__).exception("map tile rendering failed")
                with self._lock:
                    if gen == self._generation and job[0] == "index":
                        self._map_arrays = None
            finally:
                with self._lock:
                    self._busy = False
                    self._lock.notify_all()
                    trim_due = True

    def _has_work(self) -> bool:
        if self._map_arrays is None:
            return False
        return self._index is None or not self._overview_done or bool(self._wanted)

    def _run(self, gen: int, job: tuple[str, object]) -> None:
        kind, payload = job
        if kind == "index":
            points, segments = cast("tuple[np.ndarray, np.ndarray]", payload)
            index = MapIndex(points, segments)
            with self._lock:
                if gen == self._generation:
                    self._index = index
                    self._lock.notify_all()
            self._ready()
        elif kind == "overview":
            overview = _render_overview(payload)  # type: ignore[arg-type]
            with self._lock:
                if gen == self._generation:
                    self._overview = overview
                    self._overview_done = True
                    self._lock.notify_all()
            self._ready()
        else:
            index, (scale, i, j) = cast("tuple[MapIndex, tuple[float, int, int]]", payload)
            surface = render_region(index, scale, i * TILE, j * TILE, TILE, TILE)
            blank = _is_blank(surface)
            with self._lock:
                self.rendered += 1
                if gen != self._generation or scale != self._scale:  # a map or a zoom gone meanwhile
                    return
                key = (gen, scale, i, j)
                self._tiles[key] = EMPTY if blank else surface
                if not blank:
                    self._bytes += TILE * TILE * 4
                while self._bytes > self.max_bytes and self._tiles:
                    _, old = self._tiles.popitem(last=False)
                    if old is not EMPTY:
                        self._bytes -= TILE * TILE * 4
                self._lock.notify_all()
            self._ready()

    def _ready(self) -> None:
        with self._lock:
            if self._notified:
                return
            self._notified = True
        self.on_ready()


def _render_overview(index: MapIndex) -> Overview | None:
    if index.bounds is None:
        return None
    x0, y0, x1, y1 = index.bounds
    span = max(x1 - x0, y1 - y0, 1.0)
    scale = min(0.1, OVERVIEW_MAX_PX / span)
    gx0 = math.floor(x0 * scale) - 2
    gy0 = math.floor(-y1 * scale) - 2
    width = math.floor(x1 * scale) - gx0 + 3
    height = math.floor(-y0 * scale) - gy0 + 3
    return Overview(render_region(index, scale, gx0, gy0, width, height), scale, gx0, gy0)


def _is_blank(surface: cairo.ImageSurface) -> bool:
    data = np.ndarray(
        (surface.get_height(), surface.get_stride() // 4), dtype=np.uint32, buffer=surface.get_data()
    )
    return bool((data[:, : surface.get_width()] == BACKGROUND).all())

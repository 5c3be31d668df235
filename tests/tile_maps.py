"""A tile cache over a random map, indexed and ready: the set-up the tile tests share."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator

import numpy as np

from rtmu.ui.tiles import TileCache
from rtmu.ui.viewport import Viewport, fit_view

POINTS = 5000
SPAN_MM = 30000


@contextlib.contextmanager
def random_map_tiles(
    seed: int, on_ready: Callable[[], None] = lambda: None, segments: np.ndarray | None = None
) -> Iterator[TileCache]:
    """A :class:`TileCache` holding :data:`POINTS` random points over a 30 m square (seeded), its index
    built; closed afterwards."""
    cache = TileCache(on_ready)
    try:
        rng = np.random.default_rng(seed)
        cache.set_map(rng.integers(0, SPAN_MM, size=(POINTS, 2)).astype(np.int32), segments)
        assert cache.wait_idle(10), "the tile worker never finished the index"
        yield cache
    finally:
        cache.close()


def fitted(cache: TileCache, width: int, height: int) -> Viewport:
    """The view that fits the cache's map into ``width`` × ``height`` pixels."""
    assert cache.bounds is not None, "no map in the cache"
    return fit_view(cache.bounds, width, height)

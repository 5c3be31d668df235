"""The map maths and the tile renderer without a window: transforms, zoom stops, index queries, pixels."""

from __future__ import annotations

import math
import threading

import cairo
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtmu.ui.tiles import BACKGROUND, OVERVIEW_MAX_PX, TILE, MapIndex, TileCache, render_region
from rtmu.ui.viewport import ZOOM_MAX, ZOOM_MIN, ZOOM_STEPS, Viewport, fit_view, nearest_step, step_zoom
from tile_maps import fitted, random_map_tiles

coords = st.floats(-1e6, 1e6, allow_nan=False)
zooms = st.floats(0.005, 4.0)


@given(coords, coords, zooms, coords, coords)
def test_world_to_screen_and_back_is_the_identity(
    x: float, y: float, zoom: float, cx: float, cy: float
) -> None:
    vp = Viewport(800, 480, zoom, cx, cy)
    back = vp.to_world(*vp.to_screen(x, y))
    assert math.isclose(back[0], x, abs_tol=1e-6 * max(1.0, abs(x))) and math.isclose(
        back[1], y, abs_tol=1e-6 * max(1.0, abs(y))
    )


def test_y_goes_up_in_the_world_and_down_on_the_screen() -> None:
    vp = Viewport(800, 480, 1.0, 0.0, 0.0)
    assert vp.to_screen(0, 0) == (400, 240)
    assert vp.to_screen(1000, 1000) == (500, 140)  # 100 % = 10 mm per pixel


@given(zooms, st.floats(0, 800), st.floats(0, 480))
def test_zooming_keeps_the_point_under_the_anchor(zoom: float, ax: float, ay: float) -> None:
    vp = Viewport(800, 480, 0.5, 1234.0, -567.0)
    before = vp.to_world(ax, ay)
    after = vp.zoomed(zoom, (ax, ay)).to_world(ax, ay)
    assert math.dist(before, after) < 2 / (zoom * 0.1)  # within the rounding of the origin to whole pixels


def test_zoom_steps_stay_within_10_and_400_percent() -> None:
    assert ZOOM_STEPS[0] == ZOOM_MIN == 0.1 and ZOOM_STEPS[-1] == ZOOM_MAX == 4.0
    z = 1.0
    for _ in range(40):
        z = step_zoom(z, +1)
    assert z == ZOOM_MAX
    for _ in range(40):
        z = step_zoom(z, -1)
    assert z == ZOOM_MIN
    assert step_zoom(0.33, +1) == 0.4 and step_zoom(0.33, -1) == 0.3
    assert nearest_step(0.97) == 1.0


def test_fit_shows_the_whole_map_centred() -> None:
    vp = fit_view((0, 0, 30000, 12000), 800, 480)
    for corner in ((0, 0), (30000, 12000)):
        sx, sy = vp.to_screen(*corner)
        assert 0 <= sx <= 800 and 0 <= sy <= 480
    assert fit_view((0, 0, 270_000, 270_000), 800, 480).zoom < ZOOM_MIN  # a building: fit may go below 10 %


def brute_points(points: np.ndarray, x0: float, y0: float, x1: float, y1: float) -> set[tuple[int, int]]:
    keep = (points[:, 0] >= x0) & (points[:, 0] <= x1) & (points[:, 1] >= y0) & (points[:, 1] <= y1)
    return {tuple(p) for p in points[keep].tolist()}


@given(st.integers(0, 2000), st.floats(-60000, 60000), st.floats(-60000, 60000), st.floats(1, 50000))
def test_index_finds_exactly_the_points_in_a_rectangle(n: int, x0: float, y0: float, size: float) -> None:
    rng = np.random.default_rng(n)
    points = rng.integers(-50000, 50000, size=(n, 2)).astype(np.int32)
    index = MapIndex(points, np.zeros((0, 4), np.int32))
    found = {tuple(p) for p in index.points_in(x0, y0, x0 + size, y0 + size).tolist()}
    assert found == brute_points(points, x0, y0, x0 + size, y0 + size)


def pixel(surface: cairo.ImageSurface, x: int, y: int) -> int:
    data = np.ndarray((surface.get_height(), surface.get_stride() // 4), np.uint32, surface.get_data())
    return int(data[y, x]) & 0xFFFFFF


def test_a_point_lands_on_the_pixel_the_viewport_puts_it_on() -> None:
    vp = Viewport(800, 480, 1.0, 0.0, 0.0)
    index = MapIndex(np.array([[1234, -567]], np.int32), np.zeros((0, 4), np.int32))
    ox, oy = vp.origin
    sx, sy = vp.to_screen(1234, -567)
    # Tile containing the screen pixel, in global pixel coordinates (screen minus origin).
    gx, gy = math.floor(sx) - ox, math.floor(sy) - oy
    i, j = gx // TILE, gy // TILE
    tile = render_region(index, vp.scale, i * TILE, j * TILE, TILE, TILE)
    assert pixel(tile, gx - i * TILE, gy - j * TILE) != BACKGROUND & 0xFFFFFF
    assert pixel(tile, (gx - i * TILE + 5) % TILE, gy - j * TILE) == BACKGROUND & 0xFFFFFF


@pytest.mark.parametrize("count", [10, 10_000])
def test_segments_are_drawn_by_cairo_or_numpy_along_the_same_line(count: int) -> None:
    """Few segments are stroked by cairo, many are sampled with numpy: both darken the line's pixels."""
    y = np.linspace(-20000, -100, count)
    segs = np.stack([np.full(count, 0), y, np.full(count, 20000), y], axis=1).astype(np.int32)
    index = MapIndex(np.zeros((0, 2), np.int32), segs)
    tile = render_region(index, 0.1, 0, 0, TILE, TILE)
    first_row = round(-y[-1] * 0.1)
    assert pixel(tile, 100, first_row) != BACKGROUND & 0xFFFFFF
    assert pixel(tile, 100, max(0, first_row - 5)) == BACKGROUND & 0xFFFFFF


def test_tile_cache_renders_what_is_visible_off_the_calling_thread() -> None:
    ready = threading.Event()
    with random_map_tiles(1, ready.set, np.array([[0, 0, 30000, 0]], np.int32)) as cache:
        vp = fitted(cache, 800, 480)
        spots = cache.visible(vp.scale, vp.origin, vp.width, vp.height)
        assert spots and any(s.surface is None for s in spots)
        assert cache.wait_idle(10)
        spots = cache.visible(vp.scale, vp.origin, vp.width, vp.height)
        assert all(s.surface is not None for s in spots), "every visible tile is ready after the worker ran"
        assert ready.is_set() and cache.overview is not None
        cache.set_map(None, None)
        assert cache.bounds is None


def test_tile_cache_keeps_the_tiles_of_one_zoom() -> None:
    """A new zoom lets the old zoom's tiles go (issue 28: RSS): a launch's fit before the window had its
    size used to leave a screenful of tiles no frame showed again."""
    with random_map_tiles(2) as cache:
        small = fitted(cache, 600, 400)
        cache.visible(small.scale, small.origin, small.width, small.height)
        assert cache.wait_idle(10)
        first = {key[1] for key in cache._tiles}
        assert first == {small.scale}
        big = fitted(cache, 800, 480)
        assert big.scale != small.scale
        spots = cache.visible(big.scale, big.origin, big.width, big.height)
        assert cache.wait_idle(10)
        assert {key[1] for key in cache._tiles} == {big.scale}, "the old zoom's tiles are kept"
        spots = cache.visible(big.scale, big.origin, big.width, big.height)
        assert all(s.surface is not None for s in spots)
        ov = cache.overview
        assert ov is not None and max(ov.surface.get_width(), ov.surface.get_height()) <= OVERVIEW_MAX_PX + 8


def test_a_broken_map_does_not_kill_the_worker() -> None:
    cache = TileCache(lambda: None)
    try:
        cache.set_map(np.zeros((3, 3), np.int32), None)  # wrong shape: the index cannot be built
        assert cache.wait_idle(5)
        cache.set_map(np.array([[0, 0], [1000, 1000]], np.int32), None)
        assert cache.wait_idle(5) and cache.ready
    finally:
        cache.close()

"""The server's drawings in one frame drawn without a window (``drawings_draw`` via ``draw_frame``).

Each of ARIA's shapes in the server's own colour where its points are; a hidden layer, a shape
RTMU does not know and a stale robot draw nothing; a hostile size is kept to a readable size; and
the honest maximum of 3 998 points is drawn.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rtmu.ui import overlays
from rtmu.ui.frame import Scene
from rtmu.ui.viewport import Viewport
from rtmu.values.state import DrawingLayer

from .test_frame_pixels import render

W, H = 800, 400
VP = Viewport(W, H, 1.0, 0.0, 0.0)  # 0.1 px per mm: 1 m is 100 px
BLUE, SKY, RED, MAGENTA = 0x0000FF, 0x33CCFF, 0xFF0000, 0xFF00FF


def layer(name: str, shape: str, color: int, size: int, points, *, shown: bool = True, drawable: bool = True):  # type: ignore[no-untyped-def]
    return DrawingLayer(name, shape, drawable, color, size, 75, 200, shown, True, tuple(points))


def rgb(color: int) -> tuple[int, int, int]:
    return (color >> 16) & 0xFF, (color >> 8) & 0xFF, color & 0xFF


def at(pixels: np.ndarray, x_mm: float, y_mm: float) -> tuple[int, int, int]:
    sx, sy = VP.to_screen(x_mm, y_mm)
    return tuple(int(c) for c in pixels[round(sy), round(sx)])  # type: ignore[return-value]


def count(pixels: np.ndarray, color: int) -> int:
    return int(np.all(pixels == np.array(rgb(color), np.uint8), axis=-1).sum())


def frame(layers, path: Path, *, stale: bool = False) -> np.ndarray:  # type: ignore[no-untyped-def]
    scene = Scene(labels=overlays.LabelCache(), robot=(0.0, 0.0, 0.0), stale=stale, drawings=layers)
    return render(scene, VP, path)


def test_each_shape_is_drawn_in_the_servers_colour_where_its_points_are(screenshots: Path) -> None:
    laser = layer("laser", "polyDots", BLUE, 80, [(2000, 0), (2000, 500), (2000, -500)])
    sonar = layer("sonar", "polyArrows", SKY, 200, [(-2000, 0), (0, 1500)])
    path = layer("path", "polyLine", RED, 3, [(-3000, -1500), (3000, -1500)])
    segs = layer(
        "segs", "polySegments", MAGENTA, 3, [(-3000, 1700), (-1000, 1700), (1000, 1700), (3000, 1700)]
    )
    pixels = frame([laser, sonar, path, segs], screenshots / "drawings-shapes.png")
    for x, y in laser.points:
        assert at(pixels, x, y) == rgb(BLUE), (x, y)
    for x, y in sonar.points:  # the arrow's tip on the point, its shaft towards the robot
        assert at(pixels, x, y) == rgb(SKY), (x, y)
    assert at(pixels, -2000 + 120, 0) == rgb(SKY)  # 200 mm arrow: its shaft 120 mm towards the robot
    assert at(pixels, -2000 - 120, 0) != rgb(SKY)  # nothing beyond the point
    assert at(pixels, 0, -1500) == rgb(RED) and at(pixels, -2500, -1500) == rgb(RED)
    assert at(pixels, -2000, 1700) == rgb(MAGENTA) and at(pixels, 2000, 1700) == rgb(MAGENTA)
    assert at(pixels, 0, 1700) != rgb(MAGENTA)  # segments 0→1 and 2→3: nothing between 1 and 2
    # An 80 mm dot at 0.1 px/mm is 8 px across: about 50 blue pixels each.
    assert 3 * 30 <= count(pixels, BLUE) <= 3 * 70


def test_hidden_unknown_and_stale_draw_nothing(screenshots: Path) -> None:
    hidden = layer("hidden", "polyDots", BLUE, 80, [(2000, 0)], shown=False)
    unknown = layer("blob", "polyHexagons", RED, 80, [(1000, 0)], drawable=False)
    pixels = frame([hidden, unknown], screenshots / "drawings-hidden.png")
    assert count(pixels, BLUE) == 0 and count(pixels, RED) == 0
    stale = frame(
        [layer("laser", "polyDots", BLUE, 80, [(2000, 0)])], screenshots / "drawings-stale.png", stale=True
    )
    assert count(stale, BLUE) == 0  # a stale robot's readings are not shown as if they were current


def test_a_hostile_size_is_kept_readable_and_3998_points_are_drawn(screenshots: Path) -> None:
    giant = layer("giant", "polyDots", RED, 2_000_000_000, [(1000, 0)])
    many = layer(
        "many",
        "polyPoints",
        BLUE,
        1,
        [(-3500 + (i % 400) * 17, -1800 + (i // 400) * 20) for i in range(3998)],
    )
    pixels = frame([giant, many], screenshots / "drawings-hostile.png")
    assert 0 < count(pixels, RED) <= 40 * 40  # at most a 40 px dot, not the whole map
    assert count(pixels, BLUE) > 3000

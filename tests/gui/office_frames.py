"""Frames of the office map drawn without a window, for the tests of the map stage's picture and nodes."""

from __future__ import annotations

from pathlib import Path

import cairo
import numpy as np

from rtmu.ui import overlays
from rtmu.ui.frame import Scene, draw_frame
from rtmu.ui.map_layer import MapLayer
from rtmu.ui.tiles import TileCache
from rtmu.ui.viewport import Viewport, fit_view

W, H = 900, 560
TOLERANCE = 2
"""Largest difference of one colour channel allowed between the two ways (antialiasing rounding)."""


def ready(cache: TileCache, vp: Viewport) -> None:
    """Every tile of ``vp`` rendered (the worker runs on its own thread)."""
    for _ in range(20):
        if all(s.surface is not None for s in cache.visible(vp.scale, vp.origin, vp.width, vp.height)):
            return
        assert cache.wait_idle(30)
    raise AssertionError("the visible tiles never arrived")


def frame(scene: Scene, vp: Viewport, path: Path | None = None) -> np.ndarray:
    surface = cairo.ImageSurface(cairo.FORMAT_RGB24, vp.width, vp.height)
    draw_frame(cairo.Context(surface), vp, scene)
    surface.flush()
    if path is not None:
        surface.write_to_png(str(path))
    data = np.ndarray(
        (vp.height, vp.width, 4), np.uint8, surface.get_data(), strides=(surface.get_stride(), 4, 1)
    )
    return data[..., :3].astype(int).copy()


def scene_of(
    office: object, cache: TileCache, robot: tuple[float, float, float], layer: MapLayer | None
) -> Scene:
    return Scene(
        labels=overlays.LabelCache(),
        tiles=cache,
        objects=office.objects,  # type: ignore[attr-defined]
        robot=robot,
        trail=[(robot[0] - 800.0, robot[1]), robot[:2]],
        layer=layer,
    )


def named(office: object) -> list[object]:
    return [o for o in office.objects if getattr(o, "name", "") and getattr(o, "from_xy", None) is None]  # type: ignore[attr-defined]


def views(cache: TileCache, office: object) -> dict[str, tuple[Viewport, tuple[float, float, float]]]:
    fitted = fit_view(cache.bounds, W, H)  # type: ignore[arg-type]
    goal = named(office)[0]
    gx, gy = float(goal.x), float(goal.y)  # type: ignore[attr-defined]
    near = Viewport(W, H, 1.0, gx + 2500.0, gy + 1500.0)  # 100 %: the cairn and its name in view
    return {
        "fitted": (fitted, (gx + 3000.0, gy - 2000.0, 30.0)),
        "zoomed": (near, (gx + 2500.0, gy + 1500.0, 90.0)),
    }

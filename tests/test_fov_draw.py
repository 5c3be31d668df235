"""The camera's field of view on the map, drawn without a window by the window's own frame function."""

from __future__ import annotations

import math

import cairo
import numpy as np

from rtmu.ui import overlays
from rtmu.ui.fov_draw import Wedge, wedge_points
from rtmu.ui.frame import Scene, draw_frame
from rtmu.ui.viewport import Viewport

VP = Viewport(400, 300, 1.0, 0.0, 0.0)


def frame(fov: Wedge | None, th: float = 0.0) -> np.ndarray:
    surface = cairo.ImageSurface(cairo.FORMAT_RGB24, VP.width, VP.height)
    draw_frame(cairo.Context(surface), VP, Scene(labels=overlays.LabelCache(), robot=(0.0, 0.0, th), fov=fov))
    surface.flush()
    data = np.ndarray(
        (VP.height, VP.width, 4), np.uint8, surface.get_data(), strides=(surface.get_stride(), 4, 1)
    )
    return data[..., 2::-1].astype(int)  # BGRX → RGB


def ahead(vp: Viewport, th_deg: float, mm: float) -> tuple[int, int]:
    x, y = vp.to_screen(mm * math.cos(math.radians(th_deg)), mm * math.sin(math.radians(th_deg)))
    return round(y), round(x)


def amber(px: np.ndarray) -> bool:
    r, g, b = px
    return r - b > 25 and r >= g


def test_the_wedge_is_drawn_ahead_of_the_camera_and_nowhere_behind() -> None:
    for th, pan in ((0.0, 0.0), (90.0, 0.0), (30.0, 45.0)):
        with_wedge = frame(Wedge(0.0, 0.0, th, pan=pan), th)
        without = frame(None, th)
        front = ahead(VP, th + pan, 1000.0)
        back = ahead(VP, th + pan + 180.0, 1000.0)
        assert amber(with_wedge[front]) and not amber(without[front]), (th, pan, with_wedge[front])
        assert (with_wedge[back] == without[back]).all(), "nothing behind the camera"
        outside = ahead(VP, th + pan + 40.0, 1000.0)  # the wedge is 48° wide: 40° off its axis is outside
        assert (with_wedge[outside] == without[outside]).all()


def test_zoom_narrows_the_wedge_and_it_stays_visible_zoomed_out() -> None:
    wide = wedge_points(VP, Wedge(0, 0, 0, fov=48.0))
    tele = wedge_points(VP, Wedge(0, 0, 0, fov=4.0))
    spread = lambda pts: max(p[1] for p in pts) - min(p[1] for p in pts)  # noqa: E731
    assert spread(tele) < spread(wide) / 5
    far_out = Viewport(400, 300, 0.01, 0.0, 0.0)
    pts = wedge_points(far_out, Wedge(0, 0, 0))
    assert max(p[0] for p in pts) - pts[0][0] >= 39, "a minimum on-screen reach"

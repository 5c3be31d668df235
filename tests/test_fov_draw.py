"""The camera's field of view on the map, drawn without a window by the window's own frame function."""

from __future__ import annotations

import math
from dataclasses import replace

import cairo
import numpy as np

from rtmu.sim.camera import PanTiltZoom
from rtmu.ui import overlays
from rtmu.ui.fov_draw import TELE_FOV_DEG, WIDE_FOV_DEG, Wedge, camera_aim, wedge_points, zoom_fov
from rtmu.ui.frame import Scene, draw_frame
from rtmu.ui.viewport import Viewport
from rtmu.values.state import PtzState

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
        heading = th - pan  # ARIA's pan turns to the right (clockwise), the map counter-clockwise
        front = ahead(VP, heading, 1000.0)
        back = ahead(VP, heading + 180.0, 1000.0)
        assert amber(with_wedge[front]) and not amber(without[front]), (th, pan, with_wedge[front])
        assert (with_wedge[back] == without[back]).all(), "nothing behind the camera"
        outside = ahead(VP, heading + 40.0, 1000.0)  # the wedge is 48° wide: 40° off its axis is outside
        assert (with_wedge[outside] == without[outside]).all()


def test_zoom_narrows_the_wedge_and_it_stays_visible_zoomed_out() -> None:
    wide = wedge_points(VP, Wedge(0, 0, 0, fov=48.0))
    tele = wedge_points(VP, Wedge(0, 0, 0, fov=4.0))
    spread = lambda pts: max(p[1] for p in pts) - min(p[1] for p in pts)  # noqa: E731
    assert spread(tele) < spread(wide) / 5
    far_out = Viewport(400, 300, 0.01, 0.0, 0.0)
    pts = wedge_points(far_out, Wedge(0, 0, 0))
    assert max(p[0] for p in pts) - pts[0][0] >= 39, "a minimum on-screen reach"


def test_the_head_pans_and_zooms_the_wedge_as_the_simulated_vc_c4_sees() -> None:
    """The client's optics agree with the simulator's camera; pan turns the wedge clockwise."""
    for zoom in (0.0, 25.0, 50.0, 100.0):
        assert math.isclose(zoom_fov(zoom), PanTiltZoom(zoom=zoom).fov_deg, rel_tol=1e-9)
    assert camera_aim(None) == (0.0, WIDE_FOV_DEG)
    unread = PtzState(camera="Cam1", zoom_range=(0.0, 100.0), zoom_available=True)
    assert camera_aim(unread) == (0.0, WIDE_FOV_DEG)
    head = replace(unread, position=(60.0, 5.0, 100.0))
    pan, fov = camera_aim(head)
    assert pan == 60.0 and math.isclose(fov, TELE_FOV_DEG)
    assert camera_aim(replace(head, zoom_available=False))[1] == WIDE_FOV_DEG
    assert camera_aim(replace(head, position=(float("nan"), 0.0, float("inf")))) == (0.0, WIDE_FOV_DEG)

    # Drawn: panned 60° right and fully zoomed, the wedge is a narrow beam at -60°, none at 0°.
    with_head = frame(Wedge(0.0, 0.0, 0.0, pan, fov))
    without = frame(None)
    assert amber(with_head[ahead(VP, -60.0, 1500.0)])
    assert not amber(with_head[ahead(VP, 0.0, 1500.0)]), "no longer straight ahead"
    assert not amber(with_head[ahead(VP, 60.0, 1500.0)]), "right, not left"
    off_axis = ahead(VP, -60.0 + 6.0, 1500.0)  # 6° off a 4° beam's axis
    assert (with_head[off_axis] == without[off_axis]).all()

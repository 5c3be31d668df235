"""The stopping distance drawn ahead of a moving robot, by the window's own frame function (no window)."""

from __future__ import annotations

import math

import cairo
import numpy as np
import pytest

from rtmu.control.motion_limits import RobotLimits
from rtmu.ui import overlays
from rtmu.ui.frame import Scene, draw_frame
from rtmu.ui.stop_draw import StopReach, reach_corners, stop_reach
from rtmu.ui.viewport import Viewport

VP = Viewport(1000, 500, 0.32, 0.0, 0.0)
"""32 %: 0.032 px/mm, a P3-DX 14 px wide, a 4 m strip 130 px long."""


def frame(reach: StopReach | None, th: float = 0.0, stale: bool = False) -> np.ndarray:
    surface = cairo.ImageSurface(cairo.FORMAT_RGB24, VP.width, VP.height)
    scene = Scene(labels=overlays.LabelCache(), robot=(0.0, 0.0, th), stop_reach=reach, stale=stale)
    draw_frame(cairo.Context(surface), VP, scene)
    surface.flush()
    data = np.ndarray(
        (VP.height, VP.width, 4), np.uint8, surface.get_data(), strides=(surface.get_stride(), 4, 1)
    )
    return data[..., 2::-1].astype(int)


def at(th: float, mm: float) -> tuple[int, int]:
    x, y = VP.to_screen(mm * math.cos(math.radians(th)), mm * math.sin(math.radians(th)))
    return round(y), round(x)


def reddish(px: np.ndarray) -> bool:
    r, g, b = px
    return r - g > 25 and r - b > 25


@pytest.mark.parametrize("th", [0.0, 90.0, -135.0])
def test_a_moving_robot_shows_the_strip_it_sweeps_before_it_stands(th: float) -> None:
    reach = stop_reach(0.0, 0.0, th, 1500.0, RobotLimits())
    assert reach is not None and reach.distance == pytest.approx(RobotLimits().stopping_distance(1500.0))
    drawn, bare = frame(reach, th), frame(None, th)
    front = overlays.ROBOT_FRONT_MM
    inside = at(th, front + reach.distance / 2)
    end = at(th, front + reach.distance - 20)
    beyond = at(th, front + reach.distance + 400)
    behind = at(th, -1500)
    assert reddish(drawn[inside]) and not reddish(bare[inside]), drawn[inside]
    assert reddish(drawn[end]), "the bar at the end"
    assert (drawn[behind] == bare[behind]).all(), "nothing behind the robot"
    assert not reddish(drawn[beyond])


def test_reversing_draws_behind_and_standing_draws_nothing() -> None:
    reach = stop_reach(0.0, 0.0, 0.0, -375.0, RobotLimits())
    assert reach is not None
    corners = reach_corners(reach)
    assert max(x for x, _ in corners) < 0, "the strip lies behind a reversing robot"
    drawn, bare = frame(reach), frame(None)
    middle = at(0.0, -overlays.ROBOT_REAR_MM - reach.distance / 2)
    assert reddish(drawn[middle]) and not reddish(bare[middle])
    assert stop_reach(0.0, 0.0, 0.0, 10.0, RobotLimits()) is None
    assert stop_reach(0.0, 0.0, 0.0, float("nan"), RobotLimits()) is None


def test_a_stale_robot_has_no_strip_and_zoomed_far_out_it_still_shows() -> None:
    reach = stop_reach(0.0, 0.0, 0.0, 1500.0, RobotLimits())
    assert reach is not None
    inside = at(0.0, overlays.ROBOT_FRONT_MM + reach.distance / 2)
    assert not reddish(frame(reach, stale=True)[inside]), "a stale pose's speed is old news"
    far = Viewport(600, 400, 0.01, 0.0, 0.0)
    surface = cairo.ImageSurface(cairo.FORMAT_RGB24, far.width, far.height)
    draw_frame(
        cairo.Context(surface),
        far,
        Scene(labels=overlays.LabelCache(), robot=(0.0, 0.0, 0.0), stop_reach=reach),
    )
    assert reach.words == f"stops in {reach.distance / 1000:.1f} m"

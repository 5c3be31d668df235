"""The fleet's view parts without a window: ``ui.selected_model`` and ``ui.fleet_draw``.

The mirror must follow exactly the robot it was last pointed at (values, changes, trail) and
never the one before; the other robots must be in the frame's pixels in their colours.
"""

from __future__ import annotations

import itertools
import math

import cairo
import numpy as np

from rtmu.model.observables import ConnectionState, Phase, RobotModel, RobotState
from rtmu.ui.fleet_draw import FleetMark, fleet_colour, screen_polyline
from rtmu.ui.frame import Scene, draw_frame
from rtmu.ui.overlays import STALE_RGB, LabelCache
from rtmu.ui.selected_model import SelectedModel
from rtmu.ui.viewport import Viewport


def at(x: float, y: float) -> RobotState:
    return RobotState(x=x, y=y, numbers_at=1.0)


def test_the_mirror_follows_the_selected_robot_only() -> None:
    one, two = RobotModel(), RobotModel()
    one.robot.set(at(0, 0))
    one.robot.set(at(500, 0))
    two.robot.set(at(0, 0))
    two.connection.set(ConnectionState(Phase.FAILED, error="gone"))
    mirror = SelectedModel(one)
    heard: list[float] = []
    trail_changes: list[int] = []
    mirror.robot.observe(lambda _o, new: heard.append(new.x))
    mirror.trail.observe(lambda: trail_changes.append(len(mirror.trail.points)))
    assert mirror.robot.value.x == 500 and list(mirror.trail.points) == [(500, 0)]
    one.robot.set(at(900, 0))
    assert heard == [900] and trail_changes == [2]
    mirror.show(two)
    assert mirror.connection.value.phase is Phase.FAILED and heard == [900, 0]
    one.robot.set(at(2000, 0))  # the robot no longer shown: the mirror does not hear it
    assert heard == [900, 0] and mirror.robot.value.x == 0
    assert list(mirror.trail.points) == list(two.trail.points)
    assert len(one.trail.points) == 3, "the mirror appended to a robot's own trail"
    mirror.close()
    two.robot.set(at(10, 10))
    assert heard == [900, 0]


def test_other_robots_are_in_the_frame_in_their_colours_and_grey_when_stale() -> None:
    vp = Viewport(400, 300, 0.1, 200.0, 150.0)  # 1 px = 10 mm, world origin in the middle
    live = FleetMark(-1000.0, 0.0, 0.0, fleet_colour(1), False, np.array([(-1500.0, 0.0), (-1000.0, 0.0)]))
    stale = FleetMark(1000.0, 0.0, 0.0, fleet_colour(2), True, ())
    surface = cairo.ImageSurface(cairo.FORMAT_RGB24, 400, 300)
    draw_frame(cairo.Context(surface), vp, Scene(labels=LabelCache(), others=(live, stale)))
    data = np.ndarray((300, 400, 4), np.uint8, surface.get_data())[:, :, 2::-1]  # BGRx → RGB

    def near(xy: tuple[float, float], rgb: tuple[float, float, float]) -> int:
        x, y = vp.to_screen(*xy)
        patch = data[round(y) - 6 : round(y) + 7, round(x) - 6 : round(x) + 7].astype(int)
        return int((np.abs(patch - np.array(rgb) * 255).max(axis=2) < 40).sum())

    assert near((-1000.0, 0.0), fleet_colour(1)) > 20
    assert near((1000.0, 0.0), STALE_RGB) > 20 and near((1000.0, 0.0), fleet_colour(2)) == 0


def test_a_trail_is_stroked_without_points_on_the_same_pixels() -> None:
    vp = Viewport(400, 300, 0.1, 200.0, 150.0)
    trail = [(float(i), 0.0) for i in range(0, 3000, 5)]  # 600 points, 0.5 px apart
    xy = screen_polyline(vp, trail)
    assert len(xy) <= 160 and tuple(xy[-1]) == vp.to_screen(*trail[-1])
    assert all(math.dist(a, b) <= 4.0 for a, b in itertools.pairwise(xy))


def test_the_selected_model_mirrors_every_part_of_a_robot_model() -> None:
    """A part added to RobotModel (drawings, …) must reach the widgets of a fleet window too."""
    from rtmu.model.observables import Observable, RobotModel
    from rtmu.ui.selected_model import PARTS, SelectedModel

    source = RobotModel()
    observables = {n for n, v in vars(source).items() if isinstance(v, Observable)}
    assert observables <= set(PARTS) and {"robot", "drawings", "popups"} <= observables
    mirror = SelectedModel(source)
    for name in observables:
        assert isinstance(getattr(mirror, name), Observable), name

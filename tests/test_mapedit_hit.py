"""The map editor's hit rule (``rtmu.mapedit.hit``) and the free names a click-placed goal gets."""

from __future__ import annotations

import pytest

from rtmu.mapedit import MapDraft, MapObject
from rtmu.mapedit.hit import object_at

GOAL = MapObject("Goal", 1000, 1000, name="Desk")
DOCK = MapObject("Dock", 1100, 1000, 90, name="Charger")
LINE = MapObject("ForbiddenLine", 0, 0, from_xy=(0, 3000), to_xy=(4000, 3000))
BIG = MapObject("ForbiddenArea", 0, 0, from_xy=(-5000, -5000), to_xy=(5000, 5000))
SMALL = MapObject("ForbiddenArea", 0, 0, from_xy=(2000, -1000), to_xy=(3000, 0))
HOME = MapObject("RobotHome", 1000, 1000, name="Home")
ALL = (BIG, SMALL, LINE, GOAL, DOCK, HOME)


@pytest.mark.parametrize(
    ("x", "y", "reach", "expected"),
    [
        (1010, 990, 50, GOAL),  # the nearer of two points
        (1090, 1000, 50, DOCK),
        (1050, 1000, 10, BIG),  # between the two, out of reach of both: the area under them
        (2000, 3030, 50, LINE),  # near the line's middle
        (4040, 3000, 50, LINE),  # past its end, within reach of the end
        (4100, 3000, 50, BIG),
        (2500, -500, 50, SMALL),  # nested areas: the smallest holding the point
        (9000, 9000, 50, None),  # nothing: the map itself (it pans)
    ],
)
def test_the_object_a_press_means(x: float, y: float, reach: float, expected: MapObject | None) -> None:
    assert object_at(ALL, x, y, reach) is expected


def test_a_point_beats_a_line_and_an_area_it_lies_on() -> None:
    on_line = MapObject("Goal", 2000, 3000, name="On the line")
    assert object_at((BIG, LINE, on_line), 2005, 3000, 50) is on_line


def test_a_turned_area_is_hit_where_it_is_drawn() -> None:
    # ARIA turns an area by its heading about the map's origin: (1000..2000, -100..100) at 90° lies
    # along the y axis, at x -100..100, y 1000..2000.
    turned = MapObject("ForbiddenArea", 0, 0, 90, from_xy=(1000, -100), to_xy=(2000, 100))
    assert object_at((turned,), 0, 1500, 1) is turned
    assert object_at((turned,), 1500, 0, 1) is None


def test_only_editable_kinds_are_taken() -> None:
    assert object_at((HOME,), 1000, 1000, 50) is None


def test_free_names_skip_the_taken_ones_case_blind() -> None:
    draft = MapDraft([MapObject("Goal", 0, 0, name="goal 1"), MapObject("Goal", 0, 0, name="Goal 2")])
    assert draft.free_name("Goal") == "Goal 3"
    assert MapDraft([]).free_name("Dock") == "Dock 1"

"""The toolbar's words for the localization score, distance left and closest obstacle: shown only
when the server gives them, one scale whichever server (ARNL 0–1, an LD robot's data store 0–100)."""

from __future__ import annotations

from rtmu.model.observables import RobotState
from rtmu.ui.ld_status import details_lines, goal_suffix
from rtmu.values.state import NavState


def test_nothing_is_said_without_values() -> None:
    assert goal_suffix(NavState()) == "" and details_lines(RobotState(), NavState()) == []


def test_distance_left_localization_and_obstacle() -> None:
    nav = NavState(remaining_mm=12_400, loc_score=0.87)
    assert goal_suffix(nav) == " — 12.4 m left"
    assert details_lines(RobotState(closest_obstacle_mm=640), nav) == [
        "Localization score: 87 %",
        "Closest obstacle: 0.64 m",
        "Distance to the goal: 12.4 m",
    ]
    assert goal_suffix(NavState(remaining_mm=None)) == ""  # no goal

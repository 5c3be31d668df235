"""The toolbar's words for LD data-store values: shown only when the server gives them."""

from __future__ import annotations

from rtmu.model.observables import RobotState
from rtmu.ui.ld_status import details_lines, goal_suffix


def test_nothing_is_said_without_values() -> None:
    assert goal_suffix(RobotState()) == "" and details_lines(RobotState()) == []


def test_distance_left_localization_and_obstacle() -> None:
    robot = RobotState(goal_distance_mm=12_400, loc_score=87, closest_obstacle_mm=640)
    assert goal_suffix(robot) == " — 12.4 m left"
    assert details_lines(robot) == [
        "Localization score: 87 %",
        "Closest obstacle: 0.64 m",
        "Distance to the goal: 12.4 m",
    ]
    assert goal_suffix(RobotState(goal_distance_mm=0)) == ""  # 0: no goal

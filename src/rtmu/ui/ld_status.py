"""What the status toolbar shows from an LD robot's ``DataStore_*`` values: pure text, no widgets.

Why separate: the toolbar only composes; these words are tested without a window. Each part
appears only when the server lists the value (the model field is None otherwise).
"""

from __future__ import annotations

from ..model.observables import RobotState


def goal_suffix(robot: RobotState) -> str:
    """ " — 12.4 m left" while the robot has a goal (``DataStore_Distance_To_Goal`` > 0)."""
    mm = robot.goal_distance_mm
    return f" — {mm / 1000:.1f} m left" if mm else ""


def details_lines(robot: RobotState) -> list[str]:
    """Tooltip lines for the mode cell: localization score, closest obstacle, distance to goal."""
    lines = []
    if robot.loc_score is not None:
        lines.append(f"Localization score: {robot.loc_score} %")
    if robot.closest_obstacle_mm is not None:
        lines.append(f"Closest obstacle: {robot.closest_obstacle_mm / 1000:.2f} m")
    if robot.goal_distance_mm:
        lines.append(f"Distance to the goal: {robot.goal_distance_mm / 1000:.1f} m")
    return lines

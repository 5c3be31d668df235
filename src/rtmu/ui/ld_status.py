"""What the status toolbar shows from an LD robot's ``DataStore_*`` values: pure text, no widgets.

Why separate: the toolbar only composes; these words are tested without a window. Each part
appears only when the server lists the value (the model field is None otherwise).
"""

from __future__ import annotations

from ..base.i18n import _
from ..values.state import NavState, RobotState


def goal_suffix(nav: NavState) -> str:
    """ " — 12.4 m left" while the robot has a goal (a path ahead, or an LD robot's own distance)."""
    mm = nav.remaining_mm
    return _(" — {value:.1f} m left").format(value=mm / 1000) if mm else ""


def details_lines(robot: RobotState, nav: NavState) -> list[str]:
    """Tooltip lines for the mode cell: localization score, closest obstacle, distance to goal."""
    lines = []
    if nav.loc_score is not None:
        lines.append(_("Localization score: {value:.0f} %").format(value=nav.loc_score * 100))
    if robot.closest_obstacle_mm is not None:
        lines.append(_("Closest obstacle: {value:.2f} m").format(value=robot.closest_obstacle_mm / 1000))
    if nav.remaining_mm:
        lines.append(_("Distance to the goal: {value:.1f} m").format(value=nav.remaining_mm / 1000))
    return lines

"""What the status toolbar shows from an LD robot's ``DataStore_*`` values: pure text, no widgets.

Why separate: the toolbar only composes; these words are tested without a window. Each part
appears only when the server lists the value (the model field is None otherwise).
"""

from __future__ import annotations

from ..base.i18n import _
from ..base.units import metres, percent
from ..values.state import NavState, RobotState


def goal_suffix(nav: NavState) -> str:
    """ " — 12.4 m left" while the robot has a goal (a path ahead, or an LD robot's own distance)."""
    mm = nav.remaining_mm
    return _(" — {distance} left").format(distance=metres(mm)) if mm else ""


def details_lines(robot: RobotState, nav: NavState) -> list[str]:
    """Tooltip lines for the mode cell: localization score, closest obstacle, distance to goal."""
    lines = []
    if nav.loc_score is not None:
        lines.append(_("Localization score: {percent}").format(percent=percent(nav.loc_score * 100)))
    if robot.closest_obstacle_mm is not None:
        lines.append(_("Closest obstacle: {distance}").format(distance=metres(robot.closest_obstacle_mm, 2)))
    if nav.remaining_mm:
        lines.append(_("Distance to the goal: {distance}").format(distance=metres(nav.remaining_mm)))
    return lines

"""Every jog ends with an outcome the operator sees: "Went 2.00 m", "Stopped by an obstacle after 0.58 m of
2.00 m", "Turned 90°" (GTK-free).

ARIA's jog mode (``ArServerModeJogPosition``: ``moveDist``, ``turnByAngle``) sets its status to
"Moving 2000 mm" when asked and never changes it again — not when it arrives, not when its
decelerating limiter stops it short of a wall. So the outcome is read from the robot itself: the
pose when the jog was sent, then the robot's updates until it has stood still for
:data:`SETTLE_S` (or never moved within :data:`START_S`). A move that ends short says why where the
robot says it: stalled (its status), an obstacle ahead in its sonar or laser readings, or plainly
"stopped short". A stop, a drive or a navigation that takes over ends it with what was done so far.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..base.i18n import _
from ..base.units import metres, quantity
from ..values.state import RobotState

SETTLE_S = 0.5
"""Standing still this long after moving ends a jog."""
START_S = 3.0
"""A jog that has not moved after this long did not start."""
DONE_MM = 40.0
"""A move within this (or 3 %) of its distance reached it."""
DONE_DEG = 3.0
STILL_MM_S = 5.0
STILL_DEG_S = 1.0
AHEAD_MM = 900.0
"""An echo this close in front (or behind, reversing) of the robot's centre is the obstacle."""
SIDE_MM = 320.0
"""…and within this of its centre line (a P3-DX is 425 mm wide)."""


@dataclass(frozen=True, slots=True)
class Jog:
    kind: str
    """``move`` (mm) or ``turn`` (degrees, positive = left)."""
    amount: float
    x: float
    y: float
    th: float
    started: float
    moved: bool = False
    still_since: float | None = None


def _name(jog: Jog) -> str:
    return _("Go a distance") if jog.kind == "move" else _("Turn")


def _degrees(deg: float) -> str:
    return quantity(abs(deg), "deg")


def _metres(mm: float) -> str:
    return metres(abs(mm), 2)


def _turned(th0: float, th1: float) -> float:
    return math.remainder(th1 - th0, 360.0)


def obstacle_ahead(robot: RobotState, forwards: bool) -> float | None:
    """The nearest sonar or laser echo in the robot's way (mm from its centre), None if none."""
    c, s = math.cos(math.radians(robot.th)), math.sin(math.radians(robot.th))
    nearest: float | None = None
    for px, py in (*robot.sonar, *robot.laser):
        dx, dy = px - robot.x, py - robot.y
        along, side = dx * c + dy * s, -dx * s + dy * c
        along = along if forwards else -along
        if 0 < along <= AHEAD_MM and abs(side) <= SIDE_MM and (nearest is None or along < nearest):
            nearest = along
    return nearest


class JogWatch:
    """One jog at a time; :meth:`update` returns its outcome once, then forgets it."""

    def __init__(self) -> None:
        self.jog: Jog | None = None

    def start(self, kind: str, amount: float, robot: RobotState, now: float) -> None:
        self.jog = Jog(kind, amount, robot.x, robot.y, robot.th, now)

    def done_so_far(self, robot: RobotState) -> str:
        jog = self.jog
        if jog is None:
            return ""
        if jog.kind == "move":
            return _("after {metres} of {metres2}").format(
                metres=_metres(math.hypot(robot.x - jog.x, robot.y - jog.y)), metres2=_metres(jog.amount)
            )
        return _("after turning {turned} of {amount}").format(
            turned=_degrees(_turned(jog.th, robot.th)), amount=_degrees(jog.amount)
        )

    def end(self, why: str, robot: RobotState) -> str | None:
        """Something else took over (``why``: "STOP", "a drive", "a navigation"): the outcome so far."""
        if self.jog is None:
            return None
        text = _("{name} ended by {why} {done_so_far}").format(
            name=_name(self.jog), why=_(why), done_so_far=self.done_so_far(robot)
        )
        self.jog = None
        return text

    def update(self, robot: RobotState, now: float) -> str | None:
        """The robot's latest state; the outcome text when the jog is over, else None."""
        jog = self.jog
        if jog is None:
            return None
        still = abs(robot.vel) < STILL_MM_S and abs(robot.rot_vel) < STILL_DEG_S
        if not still:
            self.jog = Jog(jog.kind, jog.amount, jog.x, jog.y, jog.th, jog.started, moved=True)
            return None
        if not jog.moved:
            if now - jog.started < START_S:
                return None
            self.jog = None
            return _("{name} did not start: the robot did not move ({value})").format(
                name=_name(jog), value=robot.status or _("no status")
            )
        if jog.still_since is None:
            self.jog = Jog(jog.kind, jog.amount, jog.x, jog.y, jog.th, jog.started, True, now)
            return None
        if now - jog.still_since < SETTLE_S:
            return None
        self.jog = None
        return self._outcome(jog, robot)

    def _outcome(self, jog: Jog, robot: RobotState) -> str:
        if jog.kind == "turn":
            turned = _turned(jog.th, robot.th)
            if abs(abs(turned) - abs(jog.amount)) <= DONE_DEG:
                return _("Turned {turned}").format(turned=_degrees(turned))
            return _("Turn stopped after {turned} of {amount}").format(
                turned=_degrees(turned), amount=_degrees(jog.amount)
            )
        went = math.hypot(robot.x - jog.x, robot.y - jog.y)
        if abs(jog.amount) - went <= max(DONE_MM, 0.03 * abs(jog.amount)):
            return _("Went {metres}").format(metres=_metres(went))
        where = _("after {metres} of {metres2}").format(metres=_metres(went), metres2=_metres(jog.amount))
        if robot.status.lower().startswith("stall"):
            return _("Stopped: the robot stalled {where}. Look before driving on.").format(where=where)
        echo = obstacle_ahead(robot, jog.amount > 0)
        if echo is not None:
            return _("Stopped by an obstacle {distance} ahead {where}").format(
                distance=metres(echo), where=where
            )
        return _("Stopped short {where}").format(where=where)

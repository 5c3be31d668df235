"""Driving a planned path within the P3-DX's limits: turn to the next corner, slow for what the sonar sees.

A :class:`Follower` turns a :class:`~rtmu.sim.planner.Plan` into one velocity command per physics step.
It never asks for more than :data:`SPEED` or :data:`TURN_SPEED` (the body adds the acceleration limits),
brakes so it can stop at the goal and at each sharp corner, and brakes for sonar echoes in the robot's
way so it stops :data:`STOP_MM` short of them. When something has kept it standing for
:data:`BLOCKED_S` it reports itself blocked (the goto mode then plans around what the sonar sees).
"""

from __future__ import annotations

import math
from enum import Enum

import numpy as np

from . import p3dx
from .planner import Plan
from .robot import Body, Command, normalize_deg

SPEED = 750.0
"""mm/s: ARNL's usual path-following speed for a Pioneer, well under its 1500 mm/s TransVelMax."""
TURN_SPEED = 60.0
"""deg/s while following (the body itself allows 100)."""
DECEL = 0.8 * p3dx.TRANS_DECEL
"""Plan stops with this, a little under what the body can do, so every stop is reached."""
ARRIVE_MM = 60.0
HEADING_TOLERANCE_DEG = 2.0
WAYPOINT_REACHED_MM = 60.0
SHARP_CORNER_DEG = 30.0
"""Corners sharper than this are reached almost stopped, and turned on the spot: no cutting past walls."""
TURN_IN_PLACE_DEG = 35.0
"""Further off course than this, the robot stops and turns before driving on."""
STOP_MM = 150.0
"""The front of the robot stops this far from a sonar echo in its way."""
CORRIDOR_MM = p3dx.RADIUS_MM + 50.0
"""Echoes further to the side than this are not in the way."""
BLOCKED_S = 1.5
OFF_PATH_MM = 800.0


class Progress(Enum):
    MOVING = "moving"
    ARRIVED = "arrived"
    BLOCKED = "blocked"
    OFF_PATH = "off path"


class Follower:
    def __init__(self, plan: Plan, heading: float | None = None) -> None:
        self.points = np.asarray(plan.points, dtype=np.float64)
        self.heading = heading
        """Degrees to face at the goal, or None to stop however the robot arrives."""
        self.index = 1 if len(self.points) > 1 else 0
        self._blocked_since: float | None = None
        self.limited_by_sonar = False

    # -- questions -------------------------------------------------------------------
    def remaining(self) -> list[tuple[int, int]]:
        """The corners still ahead, goal last (what ``getPath`` shows)."""
        return [(int(x), int(y)) for x, y in self.points[self.index :]]

    def distance_left(self, x: float, y: float) -> float:
        ahead = self.points[self.index :]
        if not len(ahead):
            return 0.0
        first = math.hypot(ahead[0, 0] - x, ahead[0, 1] - y)
        return first + float(np.hypot(*np.diff(ahead, axis=0).T).sum()) if len(ahead) > 1 else first

    # -- control -----------------------------------------------------------------------
    def step(self, body: Body, echoes: list[tuple[int, int]], now: float) -> tuple[Command, Progress]:
        goal = self.points[-1]
        while self.index < len(self.points) - 1 and self._near(body, self.points[self.index]):
            self.index += 1
        if self._off_path(body):
            return Command(0.0, 0.0), Progress.OFF_PATH
        to_goal = math.hypot(goal[0] - body.x, goal[1] - body.y)
        if self.index == len(self.points) - 1 and to_goal <= ARRIVE_MM:
            return self._finish(body)
        tx, ty = self.points[self.index]
        err = normalize_deg(math.degrees(math.atan2(ty - body.y, tx - body.x)) - body.th)
        rot = _clamp(2.5 * err, TURN_SPEED)
        if abs(err) > TURN_IN_PLACE_DEG:
            return Command(0.0, rot), self._moving(now, wanted_motion=False)
        vel = SPEED * (1.0 - abs(err) / (2 * TURN_IN_PLACE_DEG))
        vel = min(vel, math.sqrt(2.0 * DECEL * max(self.distance_left(body.x, body.y) - 10.0, 0.0)) + 30.0)
        if self.index < len(self.points) - 1:
            corner = math.hypot(tx - body.x, ty - body.y)
            vel = min(vel, math.sqrt(2.0 * DECEL * corner) + self._corner_speed(self.index))
        room = self._sonar_room(body, echoes)
        sonar_limit = math.sqrt(2.0 * DECEL * max(room - STOP_MM, 0.0))
        self.limited_by_sonar = sonar_limit < vel
        if self.limited_by_sonar:
            vel = sonar_limit if sonar_limit > 20.0 else 0.0
        return Command(vel, rot), self._moving(now, wanted_motion=True, stopped=vel == 0.0 or body.stalled)

    def _corner_speed(self, i: int) -> float:
        """How fast to pass corner ``i``: slowly (then turn on the spot) where the path bends sharply."""
        a, b, c = self.points[i - 1], self.points[i], self.points[i + 1]
        turn = normalize_deg(
            math.degrees(math.atan2(c[1] - b[1], c[0] - b[0]) - math.atan2(b[1] - a[1], b[0] - a[0]))
        )
        return 30.0 if abs(turn) > SHARP_CORNER_DEG else 150.0

    def _finish(self, body: Body) -> tuple[Command, Progress]:
        if self.heading is None:
            return Command(0.0, 0.0), (Progress.ARRIVED if body.is_stopped() else Progress.MOVING)
        err = normalize_deg(self.heading - body.th)
        if abs(err) <= HEADING_TOLERANCE_DEG and abs(body.rot_vel) < 2.0 and abs(body.vel) < 5.0:
            return Command(0.0, 0.0), Progress.ARRIVED
        want = min(TURN_SPEED, 1.5 * abs(err), math.sqrt(2.0 * p3dx.ROT_DECEL * abs(err)))
        return Command(0.0, math.copysign(max(want, 2.0), err)), Progress.MOVING

    def _moving(self, now: float, *, wanted_motion: bool, stopped: bool = False) -> Progress:
        if not (wanted_motion and stopped):
            self._blocked_since = None
            return Progress.MOVING
        if self._blocked_since is None:
            self._blocked_since = now
        return Progress.BLOCKED if now - self._blocked_since >= BLOCKED_S else Progress.MOVING

    def _near(self, body: Body, point: np.ndarray) -> bool:
        return math.hypot(point[0] - body.x, point[1] - body.y) < WAYPOINT_REACHED_MM

    def _off_path(self, body: Body) -> bool:
        a = self.points[max(self.index - 1, 0)]
        b = self.points[self.index]
        return _point_segment_distance(body.x, body.y, a, b) > OFF_PATH_MM

    @staticmethod
    def _sonar_room(body: Body, echoes: list[tuple[int, int]]) -> float:
        """Free travel ahead before the robot's front reaches an echo in its way (inf when none)."""
        if not echoes:
            return math.inf
        pts = np.asarray(echoes, dtype=np.float64)
        th = math.radians(body.th)
        dx, dy = pts[:, 0] - body.x, pts[:, 1] - body.y
        along = dx * math.cos(th) + dy * math.sin(th)
        side = -dx * math.sin(th) + dy * math.cos(th)
        ahead = (along > 0) & (np.abs(side) < CORRIDOR_MM)
        if not ahead.any():
            return math.inf
        return float((along[ahead] - p3dx.LENGTH_FRONT_MM).min())


def _clamp(value: float, limit: float) -> float:
    return max(-limit, min(limit, value))


def _point_segment_distance(x: float, y: float, a: np.ndarray, b: np.ndarray) -> float:
    ex, ey = b[0] - a[0], b[1] - a[1]
    length2 = ex * ex + ey * ey
    t = 0.0 if length2 == 0 else max(0.0, min(1.0, ((x - a[0]) * ex + (y - a[1]) * ey) / length2))
    return math.hypot(a[0] + t * ex - x, a[1] + t * ey - y)

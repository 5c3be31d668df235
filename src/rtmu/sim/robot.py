"""The simulated Pioneer 3-DX body: pose, velocities with acceleration limits, walls, battery.

A mode (see :mod:`rtmu.sim.modes`) says which velocities it wants each step;
the body gets there no faster than the P3-DX's accelerations allow, never
enters a wall (a blocked step is not taken and the robot stalls), and drains
its battery with time and motion.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import p3dx
from .geometry import Obstacles

SAFE_MARGIN_MM = 100.0
"""Safe drive stops this far short of an obstacle (front or rear of the robot's circle), by default."""


def normalize_deg(angle: float) -> float:
    """Into (-180, 180]."""
    a = math.fmod(angle, 360.0)
    if a <= -180.0:
        a += 360.0
    elif a > 180.0:
        a -= 360.0
    return a


@dataclass(slots=True)
class Command:
    """What a mode wants this step."""

    vel: float = 0.0
    rot_vel: float = 0.0
    trans_decel: float | None = None
    rot_decel: float | None = None
    safe: bool = True
    """Apply the decelerating limiter (ARIA's safe drive) to ``vel``."""


class Body:
    """Kinematics, collisions and battery of one differential-drive robot."""

    def __init__(
        self,
        obstacles: Obstacles,
        x: float = 0.0,
        y: float = 0.0,
        th: float = 0.0,
        battery_v: float = p3dx.BATTERY_FULL_V,
    ) -> None:
        self.obstacles = obstacles
        self.x = float(x)
        self.y = float(y)
        self.th = normalize_deg(float(th))
        self.vel = 0.0
        self.rot_vel = 0.0
        self.battery_v = float(battery_v)
        self.drain_scale = 1.0
        """How many times the P3-DX's own drain the pack loses (the server's configuration sets it)."""
        self.stalled = False
        """The last step pushed into an obstacle (ARIA: a motor stall)."""
        self.collisions = 0
        self.emergency_stop = False
        """Set by a hard stop (collision, watchdog): decelerate at STOP_DECEL until at rest."""
        self.odometer_mm = 0.0
        self.limited_by_obstacle = False
        self.safe_margin = {True: SAFE_MARGIN_MM, False: SAFE_MARGIN_MM}
        """Safe drive's margin ahead (True) and behind (False), mm from the round body's edge."""
        self.holds: set[str] = set()
        """Why the motors do not answer now (``estop``, ``motors`` off, ``stall``, ``fault``): while any
        is held every command is zero, and a ``stall`` keeps :attr:`stalled` set."""
        self.trans_decel = p3dx.TRANS_DECEL
        """mm/s² the body brakes at when a mode asks for a slower speed (``stop``, zero ratios):
        the robot's TransDecel, which the server's configuration may change (``Robot config``)."""
        self.rot_decel = p3dx.ROT_DECEL

    # -- queries -------------------------------------------------------------
    def is_stopped(self) -> bool:
        """ARIA's ``ArRobot::isStopped`` thresholds: |vel| < 2 mm/s and |rotVel| < 1 deg/s."""
        return abs(self.vel) < 2.0 and abs(self.rot_vel) < 1.0

    def free_distance(self, forwards: bool, look: float = 3000.0) -> float:
        """Free travel (mm) before the robot's front (or rear) would touch something, along its heading."""
        th = math.radians(self.th + (0.0 if forwards else 180.0))
        c, s = math.cos(th), math.sin(th)
        offsets = np.linspace(-p3dx.WIDTH_MM / 2, p3dx.WIDTH_MM / 2, 5)
        ox = self.x - s * offsets
        oy = self.y + c * offsets
        d = self.obstacles.cast(ox, oy, np.full(offsets.shape, th), look + p3dx.RADIUS_MM)
        # The outer rays start at the body's sides, the middle one at its centre: subtract how far
        # the round body extends forward at each offset.
        reach = np.sqrt(np.maximum(p3dx.RADIUS_MM**2 - offsets**2, 0.0))
        return max(float((d - reach).min()), 0.0)

    # -- control -------------------------------------------------------------
    def hard_stop(self) -> None:
        self.emergency_stop = True

    def step(self, dt: float, cmd: Command) -> None:
        if self.holds:  # the motors do not answer: brake hard to a standstill
            cmd = Command(0.0, 0.0, safe=False)
            self.emergency_stop = self.emergency_stop or not self.is_stopped()
        want_v, want_w = cmd.vel, cmd.rot_vel
        self.limited_by_obstacle = False
        trans_decel = cmd.trans_decel or self.trans_decel
        if cmd.safe and want_v != 0.0:
            # ARIA's decelerating limiter: keep a margin, and never go faster than what TransDecel can
            # stop in the space left; brake harder (up to an emergency stop) when already too fast.
            speed = max(abs(self.vel), abs(want_v))
            look = speed * speed / (2.0 * self.trans_decel) + 1500.0
            room = max(self.free_distance(want_v > 0, look) - self.safe_margin[want_v > 0], 0.0)
            limit = math.sqrt(2.0 * self.trans_decel * room)
            if abs(want_v) > limit:
                want_v = math.copysign(limit if limit > 10.0 else 0.0, want_v)
                self.limited_by_obstacle = True
            if abs(self.vel) > limit and (self.vel > 0) == (cmd.vel > 0):
                needed = self.vel * self.vel / (2.0 * room) if room > 1.0 else p3dx.STOP_DECEL
                trans_decel = max(trans_decel, min(needed, p3dx.STOP_DECEL))
        if self.emergency_stop:
            want_v, want_w = 0.0, 0.0
            self.vel = _approach(self.vel, 0.0, p3dx.STOP_DECEL, p3dx.STOP_DECEL, dt)
            self.rot_vel = _approach(self.rot_vel, 0.0, p3dx.STOP_DECEL, p3dx.STOP_DECEL, dt)
            if self.vel == 0.0 and self.rot_vel == 0.0:
                self.emergency_stop = False
        else:
            want_v = max(-p3dx.ABSOLUTE_MAX_VEL, min(p3dx.ABSOLUTE_MAX_VEL, want_v))
            want_w = max(-p3dx.ABSOLUTE_MAX_ROT_VEL, min(p3dx.ABSOLUTE_MAX_ROT_VEL, want_w))
            self.vel = _approach(self.vel, want_v, p3dx.TRANS_ACCEL, trans_decel, dt)
            self.rot_vel = _approach(
                self.rot_vel, want_w, p3dx.ROT_ACCEL, cmd.rot_decel or self.rot_decel, dt
            )
        self._integrate(dt)
        if "stall" in self.holds:
            self.stalled = True
        self._drain(dt)

    def _integrate(self, dt: float) -> None:
        th0 = math.radians(self.th)
        th1 = th0 + math.radians(self.rot_vel * dt)
        mid = 0.5 * (th0 + th1)
        dist = self.vel * dt
        nx = self.x + dist * math.cos(mid)
        ny = self.y + dist * math.sin(mid)
        # Turning in place is always possible for a round robot; translation must not enter an obstacle.
        self.th = normalize_deg(math.degrees(th1))
        if dist == 0.0:
            return
        r = p3dx.RADIUS_MM
        new_clear = self.obstacles.clearance(nx, ny, r)
        if new_clear < r:
            old_clear = self.obstacles.clearance(self.x, self.y, r)
            if new_clear < old_clear or old_clear >= r:
                if not self.stalled:
                    self.collisions += 1
                self.stalled = True
                self.vel = 0.0
                self.emergency_stop = True
                return
        self.stalled = False
        self.x, self.y = nx, ny
        self.odometer_mm += abs(dist)

    def _drain(self, dt: float) -> None:
        drain = p3dx.BATTERY_IDLE_DRAIN_V_PER_S * dt
        drain += p3dx.BATTERY_MOTION_DRAIN_V_PER_M * abs(self.vel) * dt / 1000.0
        drain += p3dx.BATTERY_TURN_DRAIN_V_PER_REV * abs(self.rot_vel) * dt / 360.0
        self.battery_v = max(self.battery_v - drain * self.drain_scale, 0.0)


def _approach(current: float, target: float, accel: float, decel: float, dt: float) -> float:
    """Move ``current`` towards ``target``: ``accel`` while speeding up, ``decel`` while slowing down."""
    if current == target:
        return current
    speeding_up = (target > current >= 0.0) or (target < current <= 0.0)
    rate = accel if speeding_up else decel
    delta = rate * dt
    if abs(target - current) <= delta:
        return target
    return current + math.copysign(delta, target - current)

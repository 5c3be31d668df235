"""ARIA's server modes as the simulator plays them (protocol §4.2–4.3).

Exactly one mode is active. Each has ARIA's internal mode name (``getModeInfo``),
its display mode string and status strings (``updateStrings``), and turns the
client's last request into the velocities the body should reach this step.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass

from . import p3dx
from .robot import Body, Command, normalize_deg


def format_number(value: float) -> str:
    """How a C++ ostream prints a double by default (6 significant digits), as ARIA's jog statuses do."""
    return "%g" % value  # noqa: UP031 -- C formatting, on purpose


class Mode:
    NAME = ""
    MODE_STRING = ""
    DATA: tuple[str, ...] = ()
    """Data names that belong to this mode (``getModeDataList``)."""

    def __init__(self) -> None:
        self.status = ""

    @property
    def mode_string(self) -> str:
        return self.MODE_STRING

    @property
    def extended_status(self) -> str:
        return self.status

    @property
    def locked(self) -> bool:
        """ARIA's mode lock: another mode cannot take over at once (the dock mode while docked)."""
        return False

    @property
    def will_unlock(self) -> bool:
        """Locked, but gives way when asked (:meth:`request_unlock`), the asking mode taking over after."""
        return False

    def activate(self, body: Body, now: float) -> None:
        pass

    def deactivate(self) -> None:
        """Another mode took over."""

    def request_unlock(self) -> None:
        """Another mode wants to take over while this one is locked."""

    def command(self, body: Body, now: float, dt: float) -> Command:
        raise NotImplementedError


class StopMode(Mode):
    NAME = "stop"
    MODE_STRING = "Stop"
    DATA = ("stop",)

    def __init__(self) -> None:
        super().__init__()
        self.status = "Stopped"
        self._lock: bool | None = None
        """None: unlocked; else locked, and whether it gives way when asked (ARIA's ``lockMode``)."""

    @property
    def locked(self) -> bool:
        return self._lock is not None

    @property
    def will_unlock(self) -> bool:
        return self._lock is True

    def lock(self, will_unlock: bool) -> None:
        """ARIA's ``lockMode(willUnlockIfRequested)`` on the active stop mode (as a safety mode would)."""
        self._lock = will_unlock

    def unlock(self) -> None:
        self._lock = None

    def request_unlock(self) -> None:
        """A stop mode has nothing to finish: one that will unlock does so at once."""
        if self._lock is True:
            self._lock = None

    def deactivate(self) -> None:
        self._lock = None

    def command(self, body: Body, now: float, dt: float) -> Command:
        self.status = "Stopped" if body.is_stopped() else "Stopping"
        return Command(0.0, 0.0)


class RatioDriveMode(Mode):
    """``ArServerModeRatioDrive`` + ``ArActionRatioInput``: joystick-like percentages and a watchdog."""

    NAME = "ratioDrive"
    DATA = ("ratioDrive",)

    def __init__(self, timeout: float = 2.0) -> None:
        super().__init__()
        self.timeout = timeout
        self.trans_vel_max = p3dx.TRANS_VEL_MAX
        """Full stick forward (mm/s; backwards is a quarter): the server's configuration lowers it live."""
        self.rot_vel_max = p3dx.ABSOLUTE_MAX_ROT_VEL
        """No ratio turns faster than this (deg/s)."""
        self.safe = True
        self.trans_ratio = 0.0
        self.rot_ratio = 0.0
        self.throttle_ratio = 0.0
        self.lat_ratio = 0.0
        self.last_command = -math.inf
        self.timed_out = False
        self.timeouts = 0
        self.status = "Stopped"

    @property
    def mode_string(self) -> str:
        return "Drive" if self.safe else "UNSAFE Drive"

    def activate(self, body: Body, now: float) -> None:
        self.set_ratios(0.0, 0.0, 100.0, 0.0, now)

    def set_ratios(self, trans: float, rot: float, throttle: float, lat: float, now: float) -> None:
        """``ArActionRatioInput::setRatios``: clamp to ±100 (throttle 0..100)."""
        self.trans_ratio = _clamp(trans, -100.0, 100.0)
        self.rot_ratio = _clamp(rot, -100.0, 100.0)
        self.throttle_ratio = _clamp(throttle, 0.0, 100.0)
        self.lat_ratio = _clamp(lat, -100.0, 100.0)
        self.last_command = now

    def wants_to_move(self) -> bool:
        still = abs(self.trans_ratio) < 1e-7 and abs(self.rot_ratio) < 1e-6 and abs(self.lat_ratio) < 1e-7
        return not (still or self.throttle_ratio < 1e-6)

    def command(self, body: Body, now: float, dt: float) -> Command:
        timed_out = False
        if self.wants_to_move() and self.timeout > 1e-7 and now - self.last_command >= self.timeout:
            if not self.timed_out:
                # "Stopping the robot since teleop timed out": hard stop, ratios (and throttle) to zero,
                # keeping the time of the last real command.
                body.hard_stop()
                last = self.last_command
                self.set_ratios(0.0, 0.0, 0.0, 0.0, now)
                self.last_command = last
                self.timeouts += 1
            timed_out = True
        self.timed_out = timed_out
        cmd = self._ratio_velocities(body)
        if body.stalled:
            self.status = "Stalled"
        elif body.is_stopped():
            self.status = "Stopped"
        else:
            self.status = "Driving"
        return cmd

    def _ratio_velocities(self, body: Body) -> Command:
        throttle = self.throttle_ratio / 100.0
        full_fwd = self.trans_vel_max
        full_back = self.trans_vel_max / 4.0
        rot_stopped = p3dx.RATIO_ROT_AT_STOPPED
        rot_full = p3dx.RATIO_ROT_AT_FULL
        rot_ratio = self.rot_ratio / 100.0
        if self.trans_ratio > p3dx.RATIO_TRANS_DEAD_ZONE or self.trans_ratio < -p3dx.RATIO_TRANS_DEAD_ZONE:
            full = full_fwd if self.trans_ratio > 0 else full_back
            vel = self.trans_ratio / 100.0 * full * throttle
            speed_ratio = abs(body.vel / full_fwd)
            if abs(self.rot_ratio) < p3dx.RATIO_ROT_DEAD_ZONE:
                rot = 0.0
            else:
                rot = rot_ratio * ((rot_full - rot_stopped) * speed_ratio + rot_stopped) * throttle
        else:
            vel = 0.0
            rot = (
                0.0 if abs(self.rot_ratio) < p3dx.RATIO_ROT_DEAD_ZONE else rot_ratio * rot_stopped * throttle
            )
        rot = max(-self.rot_vel_max, min(self.rot_vel_max, rot))
        cmd = Command(vel, rot, safe=self.safe)
        # Stick pushed against the motion: brake three times harder.
        if (body.vel > 0 and self.trans_ratio < -50) or (body.vel < 0 and self.trans_ratio > 50):
            cmd.trans_decel = p3dx.TRANS_DECEL * 3
        if (body.rot_vel > 0 and self.rot_ratio < -50) or (body.rot_vel < 0 and self.rot_ratio > 50):
            cmd.rot_decel = p3dx.ROT_DECEL * 3
        return cmd


class WanderMode(Mode):
    """Drive ahead, turn away from whatever comes near, pick turns with the seeded generator."""

    NAME = "wander"
    MODE_STRING = "Wander"
    DATA = ("wander",)
    SPEED = 300.0
    AVOID_MM = 700.0

    def __init__(self, rng: random.Random) -> None:
        super().__init__()
        self.rng = rng
        self.status = "Wandering"
        self._turn = 0.0
        self._turn_until = -math.inf

    def command(self, body: Body, now: float, dt: float) -> Command:
        self.status = "Wandering"
        if now < self._turn_until:
            return Command(0.0, self._turn)
        if body.free_distance(True, 1500.0) < self.AVOID_MM or body.stalled:
            left = _side_space(body, +1)
            right = _side_space(body, -1)
            direction = 1.0 if left > right else -1.0
            if abs(left - right) < 200.0:
                direction = self.rng.choice((1.0, -1.0))
            self._turn = direction * 40.0
            self._turn_until = now + self.rng.uniform(0.6, 1.8)
            return Command(0.0, self._turn)
        wobble = self.rng.uniform(-8.0, 8.0) if self.rng.random() < 0.02 else 0.0
        return Command(self.SPEED, wobble)


class JogMode(Mode):
    """``ArServerModeJogPosition``: move a distance, turn by an angle, turn to a heading."""

    NAME = "jogPositionMode"
    MODE_STRING = "Jog"
    DATA = ("moveDist", "turnByAngle", "turnToHeading")

    def __init__(self) -> None:
        super().__init__()
        self.status = ""
        self._distance: float | None = None
        self._start = (0.0, 0.0)
        self._heading: float | None = None

    def move(self, body: Body, distance: float) -> None:
        self._heading = None
        self._distance = distance
        self._start = (body.x, body.y)
        self.status = f"Moving {format_number(distance)} mm"

    def turn_by(self, body: Body, angle: float) -> None:
        self._distance = None
        self._heading = normalize_deg(body.th + angle)
        self.status = f"Turning by {format_number(angle)} deg"

    def turn_to(self, heading: float) -> None:
        self._distance = None
        self._heading = normalize_deg(heading)
        self.status = f"Turning to heading {format_number(heading)} deg"

    def command(self, body: Body, now: float, dt: float) -> Command:
        if self._distance is not None:
            done = math.hypot(body.x - self._start[0], body.y - self._start[1])
            remaining = abs(self._distance) - done
            if remaining <= 2.0:
                self._distance = None
                return Command(0.0, 0.0)
            speed = min(p3dx.JOG_SPEED, math.sqrt(2.0 * p3dx.JOG_DECEL * remaining))
            return Command(math.copysign(speed, self._distance), 0.0)
        if self._heading is not None:
            err = normalize_deg(self._heading - body.th)
            if abs(err) < 0.5 and abs(body.rot_vel) < 2.0:
                self._heading = None
                return Command(0.0, 0.0)
            # Proportional heading control, bounded by what RotDecel can still stop.
            want = min(p3dx.ROT_VEL_MAX, 1.5 * abs(err), math.sqrt(2.0 * p3dx.ROT_DECEL * abs(err)))
            return Command(0.0, math.copysign(max(want, 2.0), err))
        return Command(0.0, 0.0)


@dataclass
class ModeInfo:
    name: str
    locked: bool = False
    will_unlock: bool = False


def _clamp(value: float, lo: float, hi: float) -> float:
    if value != value:  # NaN from a peer: treat as 0
        return 0.0
    return max(lo, min(hi, value))


def _side_space(body: Body, side: int) -> float:
    import numpy as np

    th = math.radians(body.th + side * 60.0)
    d = body.obstacles.cast(body.x, body.y, np.array([th]), 3000.0)
    return float(min(d[0], 3000.0))

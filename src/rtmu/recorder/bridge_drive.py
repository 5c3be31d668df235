"""Driving from Foxglove: Twist messages → the session's drive lease, one client at a time.

:class:`TwistDrive` holds the stream's rules: motion only while messages keep coming at 5 Hz or more,
the lease (220 ms) lapses and the session stops the robot when they cease, and a lease ended by
anything else (a stale link, a stop) needs a pause in the stream before the same stream can drive
again. It is the only way a Foxglove client reaches the lease: the lease is the session's own
(:class:`~rtmu.client.lease.DriveLease`), with the guardian and the stop rules of every drive.

:class:`DriveArbiter` lets one client drive at a time. The first client whose stream arrives holds
the drive until it goes quiet for :data:`HANDOVER` s, unadvertises or leaves; meanwhile every other
client's drive messages are refused — not mixed in — and that client is told why.
"""

from __future__ import annotations

import json
import math
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

from ..client.lease import DriveLease, DriveRatios, EndReason

MAX_GAP = 0.2
"""Seconds between drive messages above which the stream no longer drives (5 Hz)."""
LEASE_TTL = 0.22
"""The drive lease of a bridge's session (``ClientRunner(lease_ttl=…)``): a stream that ends stops
the robot this long after its last message — under 300 ms with the stop's way to the robot."""
MIN_INTERVAL = 0.02
"""Drive messages closer than this (over 50 Hz) only keep the drive alive: a flood cannot make the
session send ``ratioDrive`` faster than that."""
MAX_DRIVE_MESSAGE = 4096
DRIVE_TOPICS = frozenset({"/cmd_vel"})
TWIST_SCHEMAS = frozenset({"geometry_msgs/Twist", "geometry_msgs/msg/Twist"})


@dataclass(frozen=True, slots=True)
class DriveLimits:
    max_linear: float = 1.0
    """m/s in a Twist that means full forward ratio (Foxglove's Teleop sends 1.0 by default)."""
    max_angular: float = 1.0
    """rad/s that means a full turn ratio."""
    throttle: float = 50.0
    """The throttle every bridge drive uses, %."""


def twist_ratios(data: bytes, limits: DriveLimits) -> DriveRatios | None:
    """A Twist-shaped JSON message → drive ratios; None when it is not one (too big, not JSON, no numbers)."""
    if len(data) > MAX_DRIVE_MESSAGE:
        return None
    try:
        message = json.loads(data)
        linear = float(message.get("linear", {}).get("x", 0.0))
        angular = float(message.get("angular", {}).get("z", 0.0))
    except (ValueError, TypeError, AttributeError, UnicodeDecodeError, RecursionError):
        return None
    if not (math.isfinite(linear) and math.isfinite(angular)):
        return None

    def pct(value: float, full: float) -> float:
        return max(-100.0, min(100.0, value / full * 100.0))

    return DriveRatios(pct(linear, limits.max_linear), pct(angular, limits.max_angular), limits.throttle)


class TwistDrive:
    """Drive messages → the session's drive lease, by the bridge's rules. Thread-safe."""

    def __init__(self, lease: DriveLease, limits: DriveLimits, clock: Callable[[], float] = time.monotonic):
        self.lease = lease
        self.limits = limits
        self.clock = clock
        self.received = 0
        self.rejected = 0
        """Messages that were no Twist (ignored: they neither drive nor keep a drive alive)."""
        self._lock = threading.Lock()
        self._last = float("-inf")
        self._generation: int | None = None
        self._blocked = False
        """Our lease was ended by something else: the stream must pause before it drives again."""

    def message(self, data: bytes) -> None:
        ratios = twist_ratios(data, self.limits)
        with self._lock:
            if ratios is None:
                self.rejected += 1
                return
            self.received += 1
            now = self.clock()
            gap, self._last = now - self._last, now
            if gap > MAX_GAP or not ratios.moving:
                self._blocked = False  # a pause (or a zero Twist) is the stream's "key released"
            if not ratios.moving:
                self._end(EndReason.RELEASED)
                return
            if self._generation is not None:
                same = ratios == self.lease.view(now).ratios
                if gap <= MAX_GAP and (
                    self.lease.renew() if same or gap < MIN_INTERVAL else self.lease.change(ratios)
                ):
                    return
                if self.lease.ended not in (None, EndReason.LAPSED):
                    self._blocked = True  # a stop or the link ended it, not the stream
                self._end(EndReason.LAPSED)
            if gap <= MAX_GAP and not self._blocked:  # two messages within 200 ms: the stream drives
                self._generation = self.lease.grant(ratios)

    def stop(self) -> None:
        """The publishing client went away or unadvertised: stop at once."""
        with self._lock:
            self._end(EndReason.RELEASED)
            self._last = float("-inf")

    def _end(self, reason: EndReason) -> None:
        if self._generation is not None:
            self.lease.end(reason, self._generation)
            self._generation = None


HANDOVER = 1.0
"""Seconds without a drive message from the driving client before another client may drive."""


def is_drive_channel(topic: str, encoding: str, schema_name: str) -> bool:
    """A client channel whose messages drive: JSON on ``/cmd_vel`` or with a Twist schema."""
    return encoding == "json" and (topic in DRIVE_TOPICS or schema_name in TWIST_SCHEMAS)


class DriveArbiter:
    """One driving client at a time over one :class:`TwistDrive`. Thread-safe."""

    def __init__(self, drive: TwistDrive, clock: Callable[[], float] = time.monotonic) -> None:
        self.drive = drive
        self.clock = clock
        self.refused = 0
        """Drive messages refused because another client was driving."""
        self._lock = threading.Lock()
        self._driver: int | None = None
        self._last = float("-inf")

    @property
    def driver(self) -> int | None:
        """The client that drives now (None: nobody, or the last driver went quiet)."""
        with self._lock:
            return self._driver if self.clock() - self._last < HANDOVER else None

    def message(self, client: int, data: bytes) -> str | None:
        """Drive with ``client``'s message; or refuse it (the sentence the client is told)."""
        with self._lock:
            now = self.clock()
            if self._driver not in (None, client) and now - self._last < HANDOVER:
                self.refused += 1
                return (
                    f"another Foxglove client (#{self._driver}) drives the robot: your drive messages are "
                    f"ignored until it stops for {HANDOVER:g} s"
                )
            if self._driver != client:
                if self._driver is not None:
                    self.drive.stop()  # the quiet driver's drive ends before the next one's begins
                self._driver = client
            self._last = now
            self.drive.message(data)
        return None

    def release(self, client: int) -> None:
        """``client`` left or unadvertised its drive channel: if it drove, the robot stops now."""
        with self._lock:
            if self._driver == client:
                self._driver = None
                self._last = float("-inf")
                self.drive.stop()

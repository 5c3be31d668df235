"""A laser scan log (``.2d``, ARIA's ``LaserOdometryLog`` version 4) from the simulated laser.

Written as ARIA's ``ArLaserLogger`` writes one, which Mapper3 and MobilePlanner read:

* a header — ``LaserOdometryLog``, a comment, ``version: 4``, the laser's pose, field of view and name
  (``sick1pose``/``sick1conf``/``sick1name``, then ``scan1pose`` with a height, ``scan1conf``,
  ``scan1name``) and ``locationTypes: robot robotGlobal``;
* a reading block the moment the scan starts, then whenever the robot has driven more than 300 mm,
  turned more than 25° or reversed after 50 mm since the last one — ``logTime:`` (seconds since the
  start), ``velocities:``, ``scanId:``, ``robot:`` and ``robotGlobal:`` (x y mm, th °), and last
  ``scan1:`` with one ``x y`` pair per ray in the robot's frame (mm), ``0 0`` for a ray that hit nothing;
* a tag block for each tag (a loop's start or stop): ``time:``, ``robot:``, ``robotGlobal:``, the tag;
* ``# End of log`` when the scan ends.

ARIA's logger looks every robot cycle (100 ms); so does this one, in simulated time. The simulator's
odometry is exact, so ``robot`` and ``robotGlobal`` agree.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Final, TextIO

import numpy as np

from . import laser

if TYPE_CHECKING:
    from .world import World

TASK_PERIOD_S: Final = 0.1
"""ARIA's robot task cycle, at which the logger looks."""
DIST_DIFF_MM: Final = 300.0
DEG_DIFF: Final = 25.0
REVERSE_MM: Final = 50.0
_ANGLES: Final = np.radians(np.linspace(-laser.FIELD_DEG / 2, laser.FIELD_DEG / 2, laser.RAYS))


def _sub_angle(a: float, b: float) -> float:
    return (a - b + 180.0) % 360.0 - 180.0


class ScanLog:
    """One scan being written: :meth:`tick` each simulation step, :meth:`tag`, then :meth:`close`."""

    def __init__(self, path: Path, world: World) -> None:
        self.path = path
        self.world = world
        self.started = world.time
        self._out: TextIO | None = path.open("w", encoding="latin-1", newline="\n")
        self._next_look = world.time
        self._last: tuple[float, float, float] | None = None
        self._last_vel = 0.0
        self._tags: list[str] = []
        self.readings = 0
        self._header()

    def _header(self) -> None:
        half = laser.FIELD_DEG / 2
        mount = laser.MOUNT_X_MM
        self._write(
            "LaserOdometryLog\n#Created by the RTMU simulator\nversion: 4\n"
            f"sick1pose: {mount:.0f} 0 0.00\nsick1conf: {-half:.2f} {half:.2f} {laser.RAYS}\n"
            f"sick1name: {laser.NAME}\nscan1pose: {mount:.0f} 0 0 0.00\n"
            f"scan1conf: {-half:.2f} {half:.2f} {laser.RAYS}\nscan1name: {laser.NAME}\n"
            "locationTypes: robot robotGlobal\n"
        )

    def tag(self, text: str) -> None:
        """Put ``text`` in the log where the robot is at the next look (ARIA's ``addTagToLog``)."""
        self._tags.append(text)

    def tick(self) -> None:
        if self._out is None or self.world.time + 1e-9 < self._next_look:
            return
        self._next_look = self.world.time + TASK_PERIOD_S
        for text in self._tags:
            self._write(f"time: {self._elapsed()}\n{self._pose_lines()}{text}\n")
        self._tags.clear()
        if self._due():
            self._reading()

    def _due(self) -> bool:
        b = self.world.body
        if self._last is None:
            return True
        lx, ly, lth = self._last
        moved = math.hypot(b.x - lx, b.y - ly)
        reversed_ = (self._last_vel < 0 < b.vel) or (b.vel < 0 < self._last_vel)
        return (
            moved > DIST_DIFF_MM
            or abs(_sub_angle(lth, b.th)) > DEG_DIFF
            or (reversed_ and moved > REVERSE_MM)
        )

    def _reading(self) -> None:
        b = self.world.body
        self._last = (b.x, b.y, b.th)
        self._last_vel = b.vel
        pairs = "".join(f"{x} {y}  " for x, y in self.ray_points())
        self._write(
            f"logTime: {self._elapsed()}\nvelocities: {b.vel:.2f} {b.rot_vel:.2f} 0.00\n"
            f"scanId: {self.readings}\n{self._pose_lines()}scan1: {pairs}\n"
        )
        self.readings += 1

    def ray_points(self) -> list[tuple[int, int]]:
        """Each ray's hit in the robot's frame (mm, right to left); (0, 0) where it hit nothing."""
        b = self.world.body
        th = math.radians(b.th)
        ox = b.x + laser.MOUNT_X_MM * math.cos(th)
        oy = b.y + laser.MOUNT_X_MM * math.sin(th)
        ranges = self.world.obstacles.cast(ox, oy, _ANGLES + th, laser.MAX_RANGE_MM)
        hit = np.isfinite(ranges)
        safe = np.where(hit, ranges, 0.0)
        xs = np.where(hit, np.rint(laser.MOUNT_X_MM + safe * np.cos(_ANGLES)), 0).astype(np.int64)
        ys = np.where(hit, np.rint(safe * np.sin(_ANGLES)), 0).astype(np.int64)
        return list(zip(xs.tolist(), ys.tolist(), strict=True))

    def _pose_lines(self) -> str:
        b = self.world.body
        pose = f"{b.x:.0f} {b.y:.0f} {b.th:.2f}"
        return f"robot: {pose}\nrobotGlobal: {pose}\n"

    def _elapsed(self) -> str:
        ms = max(0, round((self.world.time - self.started) * 1000))
        return f"{ms // 1000}.{ms % 1000:03d}"

    def _write(self, text: str) -> None:
        if self._out is not None:
            self._out.write(text)
            self._out.flush()  # a download while scanning sees whole blocks

    def close(self) -> None:
        if self._out is not None:
            self._out.write("# End of log\n")
            self._out.close()
            self._out = None

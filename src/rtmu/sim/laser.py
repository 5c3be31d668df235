"""A simulated SICK LMS2xx on the P3-DX, as MobileSim's ``sim_lms2xx_1``: 181 rays over 180°, 1° apart.

Ray-cast like the sonar (:mod:`.sonar`) against the map's walls and points, from the laser's mount
on the robot. The readings are what ARIA's laser "current" buffer holds and what the server's
``sim_lms2xx_1Current`` drawing sends: global (x, y) mm of each ray that hit something in range.
"""

from __future__ import annotations

import math

import numpy as np

from .geometry import Obstacles

NAME = "sim_lms2xx_1"
"""The range device's name: MobileSim's first simulated LMS2xx."""
RAYS = 181
FIELD_DEG = 180.0
MAX_RANGE_MM = 32_000.0
"""The LMS200's longest reading."""
MOUNT_X_MM = 18.0
"""Where the laser sits on a P3-DX, forward of the robot's centre (ARIA's p3dx parameter ``LaserX``)."""

_ANGLES = np.radians(np.linspace(-FIELD_DEG / 2, FIELD_DEG / 2, RAYS))


def laser_readings(obstacles: Obstacles, x: float, y: float, th_deg: float) -> list[tuple[int, int]]:
    """Global (x, y) of every ray that hit something within range, rounded mm, right to left."""
    th = math.radians(th_deg)
    ox = x + MOUNT_X_MM * math.cos(th)
    oy = y + MOUNT_X_MM * math.sin(th)
    angles = _ANGLES + th
    ranges = obstacles.cast(ox, oy, angles, MAX_RANGE_MM)
    hit = np.isfinite(ranges)
    px = np.rint(ox + ranges[hit] * np.cos(angles[hit])).astype(np.int64)
    py = np.rint(oy + ranges[hit] * np.sin(angles[hit])).astype(np.int64)
    return list(zip(px.tolist(), py.tolist(), strict=True))

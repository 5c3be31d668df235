"""The P3-DX's 16 sonars, one ray each (MobileSim's "single" projection), against walls and map points."""

from __future__ import annotations

import math

import numpy as np

from . import p3dx
from .geometry import Obstacles

_DISC_X = np.array([d.x for d in p3dx.SONAR_DISCS], dtype=np.float64)
_DISC_Y = np.array([d.y for d in p3dx.SONAR_DISCS], dtype=np.float64)
_DISC_TH = np.radians(np.array([d.heading for d in p3dx.SONAR_DISCS], dtype=np.float64))


def sonar_ranges(obstacles: Obstacles, x: float, y: float, th_deg: float) -> np.ndarray:
    """Range (mm) seen by each of the 16 discs, in ARIA's order; ``inf`` when nothing is within 5 m."""
    th = math.radians(th_deg)
    c, s = math.cos(th), math.sin(th)
    ox = x + _DISC_X * c - _DISC_Y * s
    oy = y + _DISC_X * s + _DISC_Y * c
    ranges = obstacles.cast(ox, oy, _DISC_TH + th, p3dx.SONAR_MAX_RANGE_MM)
    return np.maximum(ranges, p3dx.SONAR_MIN_RANGE_MM)


def sonar_readings(obstacles: Obstacles, x: float, y: float, th_deg: float) -> list[tuple[int, int]]:
    """Global (x, y) of each echo within range, rounded mm: what ARIA's sonar "current" buffer holds."""
    th = math.radians(th_deg)
    c, s = math.cos(th), math.sin(th)
    ranges = sonar_ranges(obstacles, x, y, th_deg)
    ox = x + _DISC_X * c - _DISC_Y * s
    oy = y + _DISC_X * s + _DISC_Y * c
    ang = _DISC_TH + th
    out: list[tuple[int, int]] = []
    for i in np.flatnonzero(np.isfinite(ranges)):
        out.append((round(ox[i] + ranges[i] * math.cos(ang[i])), round(oy[i] + ranges[i] * math.sin(ang[i]))))
    return out

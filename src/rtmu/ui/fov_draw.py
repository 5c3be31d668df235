"""The camera's field of view on the map: a translucent wedge from the robot, GTK-free (cairo only).

Drawn by :func:`rtmu.ui.frame.draw_frame` under the robot, so the window and a
pixel test see the same thing. The wedge opens from the camera's heading (the
robot's heading turned by the head's pan) by its field of view; its length is a
fixed few metres — a hint of where the picture looks, not a range finder.

ARIA's camera handler sends the head's pan (degrees, positive to the right) and
zoom (% of its range) but never the lens's field of view, so :func:`camera_aim`
reads the view from a VC-C4's optics (Pioneer's usual camera, and the
simulator's): 48° wide, narrowing geometrically to 4° at full zoom.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cairo

from ..values.state import PtzState
from .viewport import Viewport

WIDE_FOV_DEG = 48.0
"""A VC-C4 at its widest; also the view of a camera without zoom or not yet read."""
TELE_FOV_DEG = 4.0
"""A VC-C4 at full zoom."""
RANGE_MM = 4000.0
MIN_RANGE_PX = 40.0
"""Zoomed far out, the wedge still reaches this far from the robot on screen."""
FILL_RGBA = (0.96, 0.62, 0.04, 0.22)
EDGE_RGBA = (0.80, 0.45, 0.0, 0.85)


def zoom_fov(zoom: float, zoom_range: tuple[float, float] = (0.0, 100.0)) -> float:
    """The horizontal field of view (degrees) at ``zoom`` within ``zoom_range``: equal zoom steps
    narrow it by equal ratios, as the simulated VC-C4's (``sim.camera.PanTiltZoom.fov_deg``)."""
    low, high = zoom_range
    if not (math.isfinite(zoom) and math.isfinite(low) and math.isfinite(high)) or high <= low:
        return WIDE_FOV_DEG
    share = min(max((zoom - low) / (high - low), 0.0), 1.0)
    return WIDE_FOV_DEG * (TELE_FOV_DEG / WIDE_FOV_DEG) ** share


def camera_aim(ptz: PtzState | None) -> tuple[float, float]:
    """(pan, field of view) in degrees from the head as last read; (0, wide) before it is read."""
    if ptz is None or ptz.position is None:
        return 0.0, WIDE_FOV_DEG
    pan, _tilt, zoom = ptz.position
    pan = pan if math.isfinite(pan) else 0.0
    fov = zoom_fov(zoom, ptz.zoom_range) if ptz.zoom_available else WIDE_FOV_DEG
    return min(max(pan, -180.0), 180.0), fov


@dataclass(frozen=True, slots=True)
class Wedge:
    """Where the camera looks from: robot pose (mm, mm, degrees counter-clockwise), the head's pan
    (degrees, positive to the right as ARIA's), field of view (degrees)."""

    x: float
    y: float
    th: float
    pan: float = 0.0
    fov: float = WIDE_FOV_DEG
    range_mm: float = RANGE_MM


def wedge_points(vp: Viewport, wedge: Wedge) -> list[tuple[float, float]]:
    """The wedge's outline on screen: apex, then points along its arc (12 steps)."""
    sx, sy = vp.to_screen(wedge.x, wedge.y)
    reach_mm = max(wedge.range_mm, MIN_RANGE_PX / max(vp.scale, 1e-9))
    heading = wedge.th - wedge.pan  # the map turns counter-clockwise, the head's pan clockwise
    half = min(max(wedge.fov, 0.5), 179.0) / 2
    points = [(sx, sy)]
    for i in range(13):
        a = math.radians(heading - half + i * (2 * half) / 12)
        points.append(vp.to_screen(wedge.x + reach_mm * math.cos(a), wedge.y + reach_mm * math.sin(a)))
    return points


def draw_fov(ctx: cairo.Context, vp: Viewport, wedge: Wedge) -> None:
    """A translucent amber wedge with a darker edge."""
    points = wedge_points(vp, wedge)
    ctx.save()
    ctx.new_path()
    ctx.move_to(*points[0])
    for p in points[1:]:
        ctx.line_to(*p)
    ctx.close_path()
    ctx.set_source_rgba(*FILL_RGBA)
    ctx.fill_preserve()
    ctx.set_source_rgba(*EDGE_RGBA)
    ctx.set_line_width(1.5)
    ctx.stroke()
    ctx.restore()

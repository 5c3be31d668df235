"""Where the robots of a simulated fleet start: apart, clear of the walls and off the map's home.

``rtmu sim --robots N`` and ``rtmu --demo --robots N`` used to put robot1 on home and the others in
a row *across* it, 900 mm apart: in the office map's 2 m corridor that put robots 2 and 3 100 mm
from the walls (the simulator then nudged them to just clear), and robot1 hid the Home marker. Here
the robots line up *along* home's heading — ahead of home first, then behind, then in rows beside
— and a spot is taken only inside the map's walls, where the robot has :data:`CLEAR_MM` of room
all round and is :data:`SPACING_MM` from every robot placed before it, from home and from every
other marker of the map (a dock, a goal: the operator must see them). robot1 takes the spot
farthest along, so the camera wedge of the robot selected first covers no other robot.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

from .geometry import Obstacles
from .p3dx import RADIUS_MM

SPACING_MM = 1500.0
"""Between neighbouring robots, and from home: a P3-DX is ~500 mm long, and at the fleet's Fit view
(~18 % at 800×480) robots drawn 900 mm apart touched each other on screen."""
CLEAR_MM = RADIUS_MM + 300.0
"""Room all round a start spot: a robot body and a hand's width more (the scan's noise, a margin)."""
MAX_STEPS = 40
"""How far along the heading (in spacings) and how many rows beside it are tried."""

Pose = tuple[float, float, float]


def _candidates(home: Pose) -> Iterator[tuple[float, float]]:
    """Spots in order of preference: ahead along home's heading, behind, then rows either side."""
    hx, hy, hth = home
    ux, uy = math.cos(math.radians(hth)), math.sin(math.radians(hth))
    for row in range(MAX_STEPS):
        side = (row + 1) // 2 * (1 if row % 2 else -1) * SPACING_MM  # 0, +1, -1, +2 …
        for sign in (1, -1):
            for step in range(1, MAX_STEPS):
                along = sign * step * SPACING_MM
                yield hx + along * ux - side * uy, hy + along * uy + side * ux


def fleet_start_poses(
    home: Pose,
    count: int,
    obstacles: Obstacles | None,
    *,
    bounds: tuple[float, float, float, float] | None = None,
    markers: tuple[tuple[float, float], ...] = (),
) -> list[Pose]:
    """``count`` start poses facing home's heading (module notes); without a map, a row ahead.
    ``bounds`` is (min x, min y, max x, max y) of the map's walls; ``markers`` its other cairns."""
    placed: list[Pose] = []
    taken = [(home[0], home[1]), *markers]
    for x, y in _candidates(home):
        if len(placed) == count:
            break
        if bounds is not None and not (bounds[0] < x < bounds[2] and bounds[1] < y < bounds[3]):
            continue
        if any(math.hypot(x - tx, y - ty) < SPACING_MM - 1.0 for tx, ty in taken):
            continue
        if obstacles is not None and obstacles.clearance(x, y, CLEAR_MM) != math.inf:
            continue
        placed.append((x, y, home[2]))
        taken.append((x, y))
    if len(placed) < count:  # a map too full for the fleet: the rest in a row ahead, as before
        hx, hy, hth = home
        ux, uy = math.cos(math.radians(hth)), math.sin(math.radians(hth))
        for i in range(len(placed), count):
            placed.append((hx + (i + 1) * SPACING_MM * ux, hy + (i + 1) * SPACING_MM * uy, hth))
    # robot1 leads the row: the window selects it first, and its camera's wedge, drawn ahead of
    # it, then covers no other robot of the fleet.
    return placed[::-1]

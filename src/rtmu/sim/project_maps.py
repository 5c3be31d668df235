"""The project's own maps, drawn in code so they can be checked and regenerated: ``rtmu/data/maps/*.map``.

* ``arena.map`` — the thesis test arena: a closed 6 m × 5 m lab room, the robot's
  home near the west wall, a goal near the east wall and three boxes between.
* ``office.map`` — an office floor, 30 m × 12 m: a corridor with rooms on both
  sides, door gaps, goals in several rooms, a forbidden server room and a
  forbidden line at the top of the stairs.

Regenerate with ``python -m rtmu.sim.project_maps [DIRECTORY]`` (default
the package's ``data/maps``, where ``rtmu.package_data`` finds them); the output is the same every time.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from rtmu.mapfile import InfoLine, MapData, MapObject, new_map, write_map
from rtmu.package_data import MAPS_DIR
from rtmu.sim.mapgen import box_segments, points_along

POINT_SPACING_MM = 20.0
"""Like a laser map at 20 mm resolution."""
NOISE_MM = 5.0


def arena_map() -> MapData:
    """The test arena: x from -1000 to 5000, y from -2500 to 2500; home at the origin facing east."""
    walls = box_segments(-1000, -2500, 5000, 2500)
    boxes = [
        box_segments(1200, -1500, 1600, -1100),
        box_segments(2300, -200, 2700, 300),  # straddles the straight line from home to the goal
        box_segments(1300, 900, 1700, 1300),
        box_segments(3300, 1000, 3700, 1500),
    ]
    segments = np.concatenate([walls, *boxes])
    objects = [
        MapObject("RobotHome", 0, 0, 0.0, name="Home"),
        MapObject("Goal", 4000, 0, 0.0, name="Goal"),
        MapObject("GoalWithHeading", 4000, -1500, -90.0, name="Far corner"),
    ]
    return _finish(segments, objects, seed=1, name="arena")


# Office floor: rooms (x0, x1) along the south (y 0–5000) and north (y 7000–12000) of the corridor.
_SOUTH_ROOMS = [(0, 4000), (4000, 9000), (9000, 14000), (14000, 20000), (20000, 25000), (25000, 30000)]
_NORTH_ROOMS = [(0, 6000), (6000, 10000), (10000, 14000), (14000, 20000), (20000, 25000), (25000, 30000)]
_CORRIDOR = (5000, 7000)
_DOOR = 1000


def office_map() -> MapData:
    """The office floor: x from 0 to 30000, y from 0 to 12000; home in the corridor's west end."""
    south_y, north_y = _CORRIDOR
    walls = [box_segments(0, 0, 30000, 12000)]
    for rooms, front_y, back_y in ((_SOUTH_ROOMS, south_y, 0), (_NORTH_ROOMS, north_y, 12000)):
        for x0, x1 in rooms:
            door = x0 + 700
            walls.append(
                np.array([[x0, front_y, door, front_y], [door + _DOOR, front_y, x1, front_y]], float)
            )
            if x0 > 0:
                walls.append(np.array([[x0, back_y, x0, front_y]], float))
    furniture = [
        box_segments(500, 500, 2000, 1300),  # Room 101 desks
        box_segments(2300, 500, 3500, 1300),
        box_segments(4500, 400, 7000, 1100),  # Room 102 desk row
        box_segments(9400, 300, 13600, 900),  # kitchen counter
        box_segments(15000, 500, 19000, 1800),  # lab bench
        box_segments(1500, 9500, 4500, 10700),  # meeting table
        box_segments(20500, 10800, 24500, 11600),  # Lab B bench
        box_segments(25500, 10500, 29500, 11700),  # storage shelves
    ]
    segments = np.concatenate(walls + furniture)
    objects = [
        MapObject("RobotHome", 2000, 6000, 0.0, name="Home"),
        MapObject("Dock", 800, 6000, 180.0, name="Charger"),
        MapObject("Goal", 2000, 3200, 0.0, name="Room 101"),
        MapObject("Goal", 6500, 3000, 0.0, name="Room 102"),
        MapObject("GoalWithHeading", 11500, 3000, -90.0, name="Kitchen"),
        MapObject("Goal", 17000, 3200, 0.0, name="Lab A"),
        MapObject("GoalWithHeading", 3000, 8300, 90.0, name="Meeting Room"),
        MapObject("Goal", 22500, 9000, 0.0, name="Lab B"),
        MapObject("Goal", 26500, 6000, 0.0, name="Corridor End"),
        MapObject(
            "ForbiddenArea", 0, 0, 0.0, name="Server Room", from_xy=(14200, 7200), to_xy=(19800, 11800)
        ),
        MapObject(
            "ForbiddenLine", 28000, 5000, 0.0, name="Stairs", from_xy=(28000, 5000), to_xy=(28000, 7000)
        ),
        MapObject("SlowArea", 0, 0, 0.0, name="Kitchen floor", from_xy=(9200, 1200), to_xy=(13800, 4800)),
    ]
    info = [
        InfoLine(
            "MapInfo",
            'SectorType Name=SlowArea "Label=Slow area" "Desc=Drive slowly here" Shape=Plain Color0=0xffcc00',
        )
    ]
    return _finish(segments, objects, seed=2, name="office", info=info)


def _finish(
    segments: np.ndarray,
    objects: list[MapObject],
    *,
    seed: int,
    name: str,
    info: list[InfoLine] | None = None,
) -> MapData:
    rng = np.random.default_rng(seed)
    points = points_along(segments, rng, spacing_mm=POINT_SPACING_MM, noise_mm=NOISE_MM)
    points = points[np.lexsort((points[:, 1], points[:, 0]))]
    result = new_map(points, segments, objects=objects, resolution=20, info=info, source=f"{name}.map")
    result.scan.points_sorted = True
    return result


PROJECT_MAPS = {"arena.map": arena_map, "office.map": office_map}


def main(argv: list[str]) -> int:
    target = Path(argv[1]) if len(argv) > 1 else MAPS_DIR
    target.mkdir(parents=True, exist_ok=True)
    for file_name, build in PROJECT_MAPS.items():
        write_map(build(), target / file_name)
        print(target / file_name)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv))

"""The robots of ``--robots 3`` start clear of the walls and off the map's home (issue 21).

Before, robot1 stood on Home (hiding its marker) and robots 2 and 3 were put 900 mm either side of
it, across the office map's 2 m corridor: 100 mm from the walls, nudged by the simulator to just
clear. What is checked is where the real simulated servers say their robots are (``updateNumbers``
over the wire), measured against the map's own walls, home and markers.
"""

from __future__ import annotations

import math

from rtmu.package_data import project_map
from rtmu.protocol.payloads.robot import UpdateNumbers
from rtmu.sim import SimConfig
from rtmu.sim.mapserve import load_map
from rtmu.sim.multi import SimFleetThreads, fleet_configs
from rtmu.sim.p3dx import RADIUS_MM
from rtmu.sim.start_spots import CLEAR_MM, SPACING_MM, fleet_start_poses

from .wire import WireClient, run

OFFICE = project_map("office.map")


def test_three_simulated_robots_start_clear_of_walls_and_off_home() -> None:
    served = load_map(OFFICE)
    walls = served.obstacles()
    markers = [(o.pose.x, o.pose.y) for o in served.objects if not o.has_from_to]  # Home, Charger, goals
    with SimFleetThreads(fleet_configs(SimConfig(port=0, map_path=OFFICE), 3)) as fleet:

        async def poses() -> list[tuple[int, int]]:
            out = []
            for sim in fleet.sims:
                c = await WireClient().open(sim.port)
                numbers = UpdateNumbers.decode((await c.ask("updateNumbers"))[0])
                out.append((numbers.x, numbers.y))
                await c.close()
            return out

        where = run(poses())
    for x, y in where:
        room = walls.clearance(x, y, 2000.0)
        assert room >= CLEAR_MM - 1, f"a robot at {(x, y)} starts {room:.0f} mm from a wall"
        for mx, my in markers:
            assert math.hypot(x - mx, y - my) > 2 * RADIUS_MM, f"a robot at {(x, y)} covers a marker"
    for i, a in enumerate(where):
        for b in where[i + 1 :]:
            assert math.hypot(a[0] - b[0], a[1] - b[1]) >= SPACING_MM - 1, f"{a} and {b} too close"


def test_a_full_map_still_gets_every_robot_a_pose() -> None:
    """A map with no room left (every spot taken by a wall) still starts each robot somewhere."""
    served = load_map(OFFICE)
    poses = fleet_start_poses((2000.0, 6000.0, 0.0), 50, served.obstacles(), bounds=(1900, 5900, 2100, 6100))
    assert len(poses) == 50 and len(set(poses)) == 50

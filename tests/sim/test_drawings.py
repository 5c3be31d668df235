"""The simulator's drawings as a client sees them over loopback: ARIA's list, the sonar and a laser."""

from __future__ import annotations

import math

from rtmu.protocol.payloads.drawings import DrawingList, DrawingListPacket, DrawingPoints, Shape
from rtmu.protocol.payloads.sensors import SensorCurrentRequest, SensorReadings
from rtmu.sim import SimConfig, SimServer
from rtmu.sim.laser import RAYS

from .wire import WireClient, run

BOX = """2D-Map
Cairn: RobotHome 0 0 0.000000 "" ICON "Home"
LINES
2000 -4000 2000 4000
-3000 -4000 -3000 4000
-3000 4000 2000 4000
-3000 -4000 2000 -4000
DATA
"""
"""A closed room: the robot at (0, 0) facing a wall 2 m ahead, walls on every side."""


async def _start(tmp_path):
    path = tmp_path / "box.map"
    path.write_text(BOX)
    server = SimServer(SimConfig(port=0, realtime=False, map_path=path))
    await server.start()
    return server, await WireClient().open(server.port)


def test_the_drawing_list_has_arias_sonar_and_laser_and_each_is_data_of_its_own(tmp_path) -> None:
    async def scenario() -> None:
        server, c = await _start(tmp_path)
        packets = [DrawingListPacket.decode(p) for p in await c.ask("getDrawingList", count=3)]
        assert packets[-1].end_of_reply
        drawings = {p.drawing.name: p.drawing for p in packets[:-1] if p.drawing is not None}
        laser, sonar = drawings["sim_lms2xx_1Current"], drawings["sonarCurrent"]
        assert (sonar.known_shape, sonar.primary_color, sonar.size, sonar.layer) == (
            Shape.POLY_ARROWS,
            0x33CCFF,
            200,
            70,
        )
        assert (laser.known_shape, laser.primary_color, laser.size, laser.layer) == (
            Shape.POLY_DOTS,
            0x0000FF,
            80,
            75,
        )
        assert (
            laser.refresh_ms == sonar.refresh_ms == 200
            and laser.visibility == sonar.visibility == "DefaultOn"
        )
        old = DrawingList.decode((await c.ask("listDrawings"))[0])
        assert {d.name for d in old.drawings} == set(drawings) and all(
            d.visibility == "" for d in old.drawings
        )
        await c.close()
        await server.stop()

    run(scenario())


def test_the_laser_sees_the_room_in_181_rays_and_matches_its_sensor_reading(tmp_path) -> None:
    async def scenario() -> None:
        server, c = await _start(tmp_path)
        points = DrawingPoints.decode((await c.ask("sim_lms2xx_1Current"))[0]).points
        # Walls all round within 32 m: every ray hits; straight ahead is the wall at x = 2000.
        assert len(points) == RAYS
        middle = points[RAYS // 2]
        assert middle[0] == 2000 and abs(middle[1]) <= 1
        assert points[0][1] < 0 < points[-1][1]  # right to left, as a SICK scans
        assert all(x >= 18 - 1 for x, _ in points)  # a 180° fan: nothing behind the mount
        on_walls = [p for p in points if p[0] == 2000 or abs(p[1]) == 4000]
        assert len(on_walls) == RAYS
        req = SensorCurrentRequest(("sim_lms2xx_1",)).encode()
        (reading,) = [SensorReadings.decode(p) for p in await c.ask("getSensorCurrent", req, count=1)]
        assert reading.readings == points
        sonar = DrawingPoints.decode((await c.ask("sonarCurrent"))[0]).points
        assert sonar and all(math.hypot(x, y) > 200 for x, y in sonar)
        await c.close()
        await server.stop()

    run(scenario())

"""What ``rtmu sim --kind aram`` serves beyond serverDemo, as a client on loopback sees it."""

from __future__ import annotations

import math

from rtmu.package_data import project_map
from rtmu.protocol.payloads.drawings import DrawingListPacket
from rtmu.protocol.payloads.drive import RatioDrive
from rtmu.protocol.payloads.ld import (
    DataStoreValue,
    DockInfo,
    DockInfoChanged,
    DockState,
    Patrol,
    Routes,
    Say,
)
from rtmu.protocol.payloads.sensors import RangeDeviceReadings
from rtmu.sim import SimConfig, SimServer
from rtmu.sim.ld_data import ROUTES, ld_state

from .wire import WireClient, eventually, run

WALL_AHEAD = """2D-Map
Cairn: RobotHome 0 0 0.000000 "" ICON "Home"
LINES
2000 -4000 2000 4000
DATA
"""


async def _start(map_path, profile: str = "aram"):
    server = SimServer(SimConfig(port=0, realtime=False, map_path=map_path, profile=profile))
    await server.start()
    return server, await WireClient().open(server.port)


def test_front_laser_sees_the_wall_at_one_ray_per_degree(tmp_path):
    path = tmp_path / "wall.map"
    path.write_text(WALL_AHEAD)

    async def scenario() -> None:
        server, c = await _start(path)
        front = RangeDeviceReadings.decode((await c.ask("Laser_1Current"))[0]).readings
        low = RangeDeviceReadings.decode((await c.ask("Laser_2Current"))[0]).readings
        # The wall at x = 2000 spans ±4 m: the main laser (240°, 15 m) sees it over ±63° (2 m ahead,
        # 4 m to each side); the low laser (126°, 4 m) only where it is within 4 m.
        assert 100 <= len(front) <= 140 and all(x == 2000 for x, _ in front)
        assert 0 < len(low) < len(front) and all(x == 2000 for x, _ in low)
        names = [DrawingListPacket.decode(p).drawing for p in await c.ask("getDrawingList", count=3)]
        assert [d.name for d in names if d] == ["Laser_1Current", "Laser_2Current"]  # no sonar on an LD
        assert "sonarCurrent" not in c.conn.datalist
        await c.close()
        await server.stop()

    run(scenario())


OFFICE = project_map("office.map")


def test_dock_drives_to_the_dock_and_a_drive_backs_out_of_it():
    """The LD dock is the simulator's dock mode: it drives there (Docking), is Docked only there, and a
    drive undocks it (it no longer "docks" on the spot and stays Docked while driving away)."""

    async def scenario() -> None:
        server, c = await _start(OFFICE)
        assert DockInfo.decode((await c.ask("dockInfo"))[0]).state == DockState.UNDOCKED
        c.request("dockInfoChanged", -1)
        await c.barrier()
        start = (server.robot.x, server.robot.y)
        c.once("dock")
        (first,) = await c.wait_for("dockInfoChanged")
        assert DockInfoChanged.decode(first).state == DockState.DOCKING
        for _ in range(600):  # at most a minute of simulated time, a second at a time
            if server.world.dock_mode.state is DockState.DOCKED:
                break
            await server.advance(1.0)
        assert DockInfo.decode((await c.ask("dockInfo"))[0]).state == DockState.DOCKED
        dock = next(d for d in server.world.nav_map.docks())
        assert math.hypot(server.robot.x - dock.x, server.robot.y - dock.y) < 100, "docked at the dock"
        assert math.hypot(server.robot.x - start[0], server.robot.y - start[1]) > 500, "it drove there"
        await eventually(lambda: len(c.received["dockInfoChanged"]) >= 2, what="the docked broadcast")
        c.once("ratioDrive", RatioDrive(50.0, 0.0, 50.0).encode())
        await c.barrier()
        await server.advance(0.2)
        assert DockInfo.decode((await c.ask("dockInfo"))[0]).state == DockState.UNDOCKING
        await server.advance(5.0)
        assert DockInfo.decode((await c.ask("dockInfo"))[0]).state == DockState.UNDOCKED
        await c.close()
        await server.stop()

    run(scenario(), timeout=120)


def test_routes_patrol_say_and_data_store(arena_map):
    async def scenario() -> None:
        server, c = await _start(arena_map)
        assert Routes.decode((await c.ask("getRoutes"))[0]).routes == ROUTES
        c.once("patrol", Patrol(ROUTES[1]).encode())
        c.once("patrol", Patrol("no such route").encode())
        c.once("say", Say("Hello from RTMU").encode())
        await c.barrier()
        state = ld_state(server)
        assert state.patrols == [ROUTES[1]]
        assert state.said == ["Hello from RTMU"]
        wifi = DataStoreValue.decode((await c.ask("DataStore_WirelessQuality"))[0]).value
        assert wifi == str(server.world.wifi().quality)
        closest = DataStoreValue.decode((await c.ask("DataStore_Closest_Obstacle_Distance"))[0]).value
        assert closest == "none" or 0 < float(closest) < math.inf
        await c.close()
        await server.stop()

    run(scenario())


def test_default_profile_lists_none_of_it(arena_map):
    async def scenario() -> None:
        server, c = await _start(arena_map, profile="default")
        assert len(c.conn.datalist) > 50  # the list did arrive
        for name in ("Laser_1Current", "dockInfo", "getRoutes", "patrol", "say", "DataStore_WirelessQuality"):
            assert name not in c.conn.datalist
        await c.close()
        await server.stop()

    run(scenario())

"""Navigation as ARNL does it, over loopback on the manual clock: goals, poses, home, tours, dock, locating.

Every scenario drives the office map (``rtmu/data/maps/office.map``; home in the corridor's west end, a
``Dock`` called Charger just west of it, a forbidden server room, a forbidden line at the stairs).
"""

from __future__ import annotations

import math
import shutil
import struct
from pathlib import Path

from rtmu.mapfile import MapObject, write_map
from rtmu.package_data import project_map
from rtmu.protocol.payloads.commands import CommandList
from rtmu.protocol.payloads.drive import RatioDrive
from rtmu.protocol.payloads.ld import DataStoreValue
from rtmu.protocol.payloads.map import Goals
from rtmu.protocol.payloads.navigation import (
    GoalName,
    GotoGoal,
    GotoPose,
    LocalizationState,
    LocalizeToPose,
    LocState,
    PathPlannerStatus,
    PlannedPath,
)
from rtmu.protocol.payloads.robot import ModeInfo, UpdateStrings
from rtmu.sim import SimConfig, SimServer
from rtmu.sim.project_maps import office_map

from .wire import WireClient, run

OFFICE = project_map("office.map")
GOALS = {o.name: o for o in office_map().objects}


async def _start(map_path: Path = OFFICE) -> tuple[SimServer, WireClient]:
    server = SimServer(SimConfig(port=0, realtime=False, map_path=map_path))
    await server.start()
    client = await WireClient().open(server.port)
    client.request("updateStrings", -1)
    client.request("getModeInfo", -1)
    await client.wait_for("getModeInfo")
    return server, client


async def _end(server: SimServer, c: WireClient) -> None:
    await c.close()
    await server.stop()


async def _until(server: SimServer, predicate, limit_s: float, step_s: float = 0.5) -> float:
    """Run the clock until ``predicate()`` holds; returns the simulated seconds it took."""
    waited = 0.0
    while not predicate():
        assert waited < limit_s, f"not within {limit_s} s of simulated time: {server.robot.status!r}"
        await server.advance(step_s)
        waited += step_s
    return waited


def _strings(c: WireClient) -> list[UpdateStrings]:
    return [UpdateStrings.decode(p) for p in c.received["updateStrings"]]


async def _last_strings(c: WireClient, status: str) -> UpdateStrings:
    """Wait for the broadcast that says ``status`` (the server sends it when the strings change)."""
    await c.until(lambda: any(s.status == status for s in _strings(c)))
    return next(s for s in _strings(c) if s.status == status)


def _distance_to(server: SimServer, x: float, y: float) -> float:
    return math.hypot(server.robot.x - x, server.robot.y - y)


def test_goto_goal_arrives_at_the_cairn_with_arnls_words():
    async def scenario() -> None:
        server, c = await _start()
        goal = GOALS["Room 101"]
        c.once("gotoGoal", GotoGoal("Room 101").encode())
        going = await _last_strings(c, "Going to Room 101")
        assert going.mode == "Goto goal"
        assert ModeInfo.decode(c.received["getModeInfo"][-1]).mode_name == "Goto"
        await server.advance(4.0)
        path = PlannedPath.decode((await c.ask("getPath"))[0]).points
        assert len(path) >= 1 and path[-1] == (int(goal.x), int(goal.y))
        assert PathPlannerStatus.decode((await c.ask("pathPlannerStatus"))[0]).status == "Moving to goal"
        assert GoalName.decode((await c.ask("goalName"))[0]).goal == "Room 101"
        assert server.robot.vel > 100 and _distance_to(server, 2000, 6000) > 200
        await _until(server, lambda: server.robot.status == "Arrived at Room 101", 60)
        arrived = await _last_strings(c, "Arrived at Room 101")
        assert arrived.mode == "Goto goal"
        assert _distance_to(server, goal.x, goal.y) <= 250
        assert server.robot.collisions == 0 and server.robot.vel == 0
        assert PlannedPath.decode((await c.ask("getPath"))[0]).points == ()
        assert PathPlannerStatus.decode((await c.ask("pathPlannerStatus"))[0]).status == "Goal reached"
        await _end(server, c)

    run(scenario())


def test_goal_with_heading_and_goto_pose_end_facing_the_heading():
    async def scenario() -> None:
        server, c = await _start()
        c.once("gotoPose", GotoPose(6500, 6000, 90).encode())
        assert (await _last_strings(c, "Going to point")).mode == "Goto point"
        await _until(server, lambda: server.robot.status == "Arrived at point", 60)
        assert _distance_to(server, 6500, 6000) <= 250
        assert abs(server.robot.th - 90) <= 3
        kitchen = GOALS["Kitchen"]  # GoalWithHeading, -90°
        c.once("gotoGoal", GotoGoal("Kitchen").encode())
        await _until(server, lambda: server.robot.status == "Arrived at Kitchen", 90)
        assert _distance_to(server, kitchen.x, kitchen.y) <= 250
        assert abs(server.robot.th - kitchen.th) <= 3
        assert server.robot.collisions == 0
        await _end(server, c)

    run(scenario())


def test_stop_and_ratio_drive_end_a_navigation_at_once():
    async def scenario() -> None:
        server, c = await _start()
        c.once("gotoGoal", GotoGoal("Corridor End").encode())
        await c.barrier()
        await server.advance(4.0)
        assert server.robot.vel > 300
        c.once("stop")
        await c.barrier()
        assert server.robot.mode_name == "stop"
        await server.advance(3.0)
        x = server.robot.x
        assert server.robot.vel == 0
        await server.advance(3.0)
        assert server.robot.x == x  # the goal is forgotten, not paused
        assert (await _last_strings(c, "Stopped")).mode == "Stop"

        c.once("gotoGoal", GotoGoal("Corridor End").encode())
        await c.barrier()
        await server.advance(4.0)
        assert server.robot.vel > 300
        c.once("ratioDrive", RatioDrive(0, 0, 100).encode())
        await c.barrier()
        assert server.robot.mode_name == "ratioDrive"
        await server.advance(3.0)
        assert server.robot.vel == 0 and server.robot.status == "Stopped"
        assert PlannedPath.decode((await c.ask("getPath"))[0]).points == ()
        await _end(server, c)

    run(scenario())


def test_unreachable_goals_fail_with_arnls_failure_text():
    async def scenario() -> None:
        server, c = await _start()
        c.once("gotoPose", GotoPose(17000, 9500).encode())  # inside the forbidden server room
        assert (await _last_strings(c, "Failed to plan to point")).mode == "Goto point"
        c.once("gotoGoal", GotoGoal("Nowhere").encode())
        await _last_strings(c, "Failed to plan to Nowhere")
        c.once("gotoPose", GotoPose(29000, 6000).encode())  # beyond the forbidden line at the stairs
        await _last_strings(c, "Failed to plan to point")
        status = PathPlannerStatus.decode((await c.ask("pathPlannerStatus"))[0]).status
        assert status.startswith("Failed to plan")
        await server.advance(2.0)
        assert server.robot.vel == 0 and _distance_to(server, 2000, 6000) < 1
        await _end(server, c)

    run(scenario())


def test_an_unmapped_obstacle_is_seen_by_the_sonar_and_the_way_reported_blocked():
    async def scenario() -> None:
        server, c = await _start()
        server.place_obstacle(9000, 5000, 9000, 7000)  # a wall across the corridor the map does not show
        c.once("gotoGoal", GotoGoal("Corridor End").encode())
        await _until(server, lambda: server.robot.status.startswith("Failed to get to Corridor End"), 120)
        failed = server.robot.status
        assert failed == "Failed to get to Corridor End (path blocked)"
        await _last_strings(c, failed)
        assert server.robot.collisions == 0  # it slowed and stopped in front of the wall
        assert 8000 < server.robot.x < 9000 - 250
        assert server.robot.vel == 0
        await _end(server, c)

    run(scenario())


def test_a_partly_blocked_corridor_is_driven_around():
    async def scenario() -> None:
        server, c = await _start()
        server.place_obstacle(9000, 5000, 9000, 6200)  # blocks the middle of the corridor, not all of it
        c.once("gotoPose", GotoPose(12000, 6000).encode())
        await _until(
            server, lambda: server.robot.status == "Arrived at point" or "Failed" in server.robot.status, 120
        )
        assert server.robot.status == "Arrived at point"
        assert server.robot.collisions == 0
        assert server.world.path_task.replans >= 1  # the map never showed the obstacle: the sonar did
        await _end(server, c)

    run(scenario())


def test_dock_charges_and_a_drive_command_undocks():
    async def scenario() -> None:
        server, c = await _start()
        charger = GOALS["Charger"]
        server.world.set_battery(11.8)
        c.once("dock")
        going = await _last_strings(c, "Going to dock at Charger")
        assert going.mode == "Dock"
        await _until(server, lambda: server.robot.status == "Docked", 90)
        assert _distance_to(server, charger.x, charger.y) <= 100
        info = ModeInfo.decode(c.received["getModeInfo"][-1])
        assert (info.mode_name, info.locked, info.will_unlock_if_requested) == ("dock", True, True)
        volts = server.robot.battery_v
        await server.advance(60.0)
        assert server.robot.battery_v > volts + 0.01  # charging beats the idle drain
        assert server.robot.status == "Docked"

        for _ in range(40):  # hold the drive key: the dock backs out first, then the drive mode takes over
            c.once("ratioDrive", RatioDrive(0, 0, 100).encode())
            await c.barrier()
            await server.advance(0.1)
            if server.robot.mode_name == "ratioDrive":
                break
        await c.barrier()
        assert any(s.status == "Undocking" for s in _strings(c))
        assert server.robot.mode_name == "ratioDrive"
        assert _distance_to(server, charger.x, charger.y) >= 500
        assert not ModeInfo.decode(c.received["getModeInfo"][-1]).locked
        await _end(server, c)

    run(scenario())


def test_dock_without_a_dock_cairn_says_so(tmp_path: Path):
    async def scenario() -> None:
        data = office_map()
        data.objects = [o for o in data.objects if o.type != "Dock"]
        path = tmp_path / "nodock.map"
        write_map(data, path)
        server, c = await _start(path)
        c.once("dock")
        assert (await _last_strings(c, "Unable to dock")).mode == "Dock"
        assert not ModeInfo.decode(c.received["getModeInfo"][-1]).locked
        await _end(server, c)

    run(scenario())


def test_lost_robot_fails_until_localized_then_navigates_again():
    async def scenario() -> None:
        server, c = await _start()
        state = LocState.decode((await c.ask("getLocState"))[0])
        assert state.state == LocalizationState.GOOD and state.score >= 900
        server.lose_localization()
        state = LocState.decode((await c.ask("getLocState"))[0])
        assert state.state == LocalizationState.LOST and state.score < 200
        c.once("gotoGoal", GotoGoal("Room 101").encode())
        await _last_strings(c, "Failed to get to Room 101 because robot lost")
        c.once("home")
        await _last_strings(c, "Failed to get home because robot lost")

        c.once("localizeToPose", LocalizeToPose(2500, 6000, 0).encode())
        await c.barrier()
        assert (server.robot.x, server.robot.y) == (2500, 6000)
        assert LocState.decode((await c.ask("getLocState"))[0]).state == LocalizationState.INITIALIZING
        await server.advance(1.0)
        state = LocState.decode((await c.ask("getLocState"))[0])
        assert state.state == LocalizationState.GOOD and state.score >= 900
        c.once("gotoGoal", GotoGoal("Room 101").encode())
        await _until(server, lambda: server.robot.status == "Arrived at Room 101", 60)
        await _end(server, c)

    run(scenario())


def test_losing_localization_on_the_way_stops_the_robot():
    async def scenario() -> None:
        server, c = await _start()
        c.once("listCommands")
        commands = CommandList.decode((await c.wait_for("listCommands"))[0]).commands
        assert "SimulatorLoseLocalization" in [e.name for e in commands]
        c.once("gotoPose", GotoPose(12000, 6000).encode())
        await c.barrier()
        await server.advance(4.0)
        c.once("SimulatorLoseLocalization")
        await c.barrier()
        await server.advance(0.1)
        assert server.robot.status == "Failed to get to point because robot lost"
        await server.advance(3.0)
        assert server.robot.vel == 0
        assert PathPlannerStatus.decode((await c.ask("pathPlannerStatus"))[0]).status == "Robot lost"
        await _end(server, c)

    run(scenario())


def test_home_and_tour_goals():
    async def scenario() -> None:
        server, c = await _start()
        c.once("gotoPose", GotoPose(6000, 6000).encode())
        await _until(server, lambda: server.robot.status == "Arrived at point", 60)
        c.once("home")
        assert (await _last_strings(c, "Returning home")).mode == "Go home"
        await _until(server, lambda: server.robot.status == "Returned home", 60)
        assert _distance_to(server, 2000, 6000) <= 250
        c.once("tourGoals")
        first = await _last_strings(c, "Touring to Room 101")
        assert first.mode == "Touring goals"
        await _until(server, lambda: server.robot.status == "Touring to Room 102", 90)
        assert GoalName.decode((await c.ask("goalName"))[0]).goal == "Room 102"
        await _end(server, c)

    run(scenario())


def test_a_reloaded_map_announces_its_goals_and_they_can_be_driven_to(tmp_path: Path):
    async def scenario() -> None:
        path = tmp_path / "office.map"
        shutil.copy(OFFICE, path)
        server, c = await _start(path)
        c.request("goalsUpdated", -1)
        await c.barrier()
        data = office_map()
        data.objects.append(MapObject("Goal", 5000, 6000, 0.0, name="Printer"))
        write_map(data, path)
        c.once("checkMap")
        await c.wait_for("goalsUpdated")
        assert "Printer" in Goals.decode((await c.ask("getGoals"))[0]).goals
        c.once("gotoGoal", GotoGoal("Printer").encode())
        await _until(server, lambda: server.robot.status == "Arrived at Printer", 60)
        await _end(server, c)

    run(scenario())


def test_goto_pose_heading_may_come_as_two_bytes():
    async def scenario() -> None:
        server, c = await _start()
        c.once("gotoPose", struct.pack("<iih", 4000, 6000, -90))
        await _until(server, lambda: server.robot.status == "Arrived at point", 60)
        assert abs(server.robot.th + 90) <= 3
        await _end(server, c)

    run(scenario())


def test_the_aram_profile_navigates_too_and_its_data_store_follows():
    async def scenario() -> None:
        server = SimServer(SimConfig(port=0, realtime=False, map_path=OFFICE, profile="aram"))
        await server.start()
        c = await WireClient().open(server.port)
        assert {"gotoGoal", "gotoPose", "localizeToPose", "getLocState", "gotoRouteGoal"} <= {
            e.name for e in c.conn.datalist
        }
        c.once("gotoGoal", GotoGoal("Room 102").encode())
        await c.barrier()
        await server.advance(3.0)
        left = float(DataStoreValue.decode((await c.ask("DataStore_Distance_to_goal"))[0]).value)
        assert 1000 < left < 8000
        await _until(server, lambda: server.robot.status == "Arrived at Room 102", 60)
        assert DataStoreValue.decode((await c.ask("DataStore_Distance_to_goal"))[0]).value == "0"
        server.lose_localization()
        assert int(DataStoreValue.decode((await c.ask("DataStore_LaserLocalizationScore"))[0]).value) < 20
        await _end(server, c)

    run(scenario())

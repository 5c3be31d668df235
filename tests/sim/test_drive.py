"""Status, driving, ARIA's watchdog, collisions and modes — over loopback, on the manual clock."""

from __future__ import annotations

from rtmu.protocol.payloads.drive import MoveDist, RatioDrive, SetSafeDrive, TurnByAngle
from rtmu.protocol.payloads.robot import ModeInfo, UpdateNumbers, UpdateStrings
from rtmu.sim import SimConfig, SimServer

from .wire import WireClient, run


async def _start(map_path=None, **kw) -> tuple[SimServer, WireClient]:
    server = SimServer(SimConfig(port=0, realtime=False, map_path=map_path, **kw))
    await server.start()
    client = await WireClient().open(server.port)
    return server, client


async def _end(server: SimServer, *clients: WireClient) -> None:
    for c in clients:
        await c.close()
    await server.stop()


async def _drive(server: SimServer, c: WireClient, ratios: RatioDrive, seconds: float) -> None:
    """Hold a key: resend ratioDrive every 100 ms of simulated time, as a client must."""
    for _ in range(round(seconds / 0.1)):
        c.once("ratioDrive", ratios.encode())
        await c.barrier()
        await server.advance(0.1)


def test_status_arrives_at_10_hz_with_aria_fields(arena_map):
    async def scenario() -> None:
        server, c = await _start(arena_map)
        c.request("updateNumbers", 100)
        await c.wait_for("updateNumbers", 1)  # a new subscription is answered at once
        await server.advance(1.0)
        got = await c.wait_for("updateNumbers", 11)
        assert len(got) == 11
        n = UpdateNumbers.decode(got[-1])
        assert (n.x, n.y, n.th, n.vel, n.rot_vel, n.lat_vel) == (0, 0, 0, 0, 0, 0)
        assert 12.7 <= n.battery <= 12.8 and n.temperature == -127
        c.request("updateNumbers", 250)  # re-request: new interval, no immediate reply
        await c.barrier()
        assert len(c.received["updateNumbers"]) == 11
        await server.advance(1.0)
        assert len(await c.wait_for("updateNumbers", 15)) == 15
        c.request_stop("updateNumbers")
        await c.barrier()
        await server.advance(1.0)
        assert len(c.received["updateNumbers"]) == 15
        await _end(server, c)

    run(scenario())


def test_drive_accelerates_like_a_p3dx_then_stop_brings_it_to_rest(arena_map):
    async def scenario() -> None:
        server, c = await _start(arena_map)
        c.request("getModeInfo", -1)
        c.request("updateStrings", -1)
        first = await c.wait_for("getModeInfo")
        assert ModeInfo.decode(first[0]).mode_name == "stop"
        assert UpdateStrings.decode((await c.wait_for("updateStrings"))[0]) == UpdateStrings(
            "Stopped", "Stop", "Stopped"
        )
        await _drive(server, c, RatioDrive(50, 0, 100), 1.0)
        # 300 mm/s² for one second, as the captured P3-DX.
        assert 270 <= server.robot.vel <= 310
        assert 100 <= server.robot.x <= 200
        assert server.robot.trans_ratio == 50 and server.robot.throttle == 100
        modes = [ModeInfo.decode(p).mode_name for p in await c.wait_for("getModeInfo", 2)]
        assert modes[-1] == "ratioDrive"
        await c.until(lambda: UpdateStrings.decode(c.received["updateStrings"][-1]).status == "Driving")
        assert UpdateStrings.decode(c.received["updateStrings"][-1]).mode == "Drive"
        c.once("stop")
        await c.barrier()
        await server.advance(2.0)
        assert server.robot.vel == 0 and server.robot.status == "Stopped"
        assert [ModeInfo.decode(p).mode_name for p in c.received["getModeInfo"]][-1] == "stop"
        last = UpdateStrings.decode(c.received["updateStrings"][-1])
        assert last == UpdateStrings("Stopped", "Stop", "Stopped")
        await _end(server, c)

    run(scenario())


def test_throttle_and_backwards_scale_as_arias_ratio_input(arena_map):
    async def scenario() -> None:
        server, c = await _start(arena_map)
        await _drive(server, c, RatioDrive(-100, 0, 100), 1.5)
        assert abs(server.robot.vel + 375) < 1  # backwards: a quarter of the maximum
        await _drive(server, c, RatioDrive(50, 0, 50), 2.5)
        assert server.robot.throttle == 50
        assert abs(server.robot.vel - 375) < 1  # 50 % of 1500 mm/s at half throttle
        await _drive(server, c, RatioDrive(0, 20, 100), 1.0)
        assert abs(server.robot.rot_vel - 10) < 0.5  # 20 % of 50 deg/s when not translating
        await _end(server, c)

    run(scenario())


def test_watchdog_stops_a_drive_that_is_not_renewed(arena_map):
    async def scenario() -> None:
        server, c = await _start(arena_map)
        c.once("ratioDrive", RatioDrive(0, 60, 100).encode())
        await c.barrier()
        await server.advance(1.9)
        assert server.robot.rot_vel > 20 and server.robot.watchdog_stops == 0
        await server.advance(0.2)
        assert server.robot.watchdog_stops == 1
        assert (server.robot.trans_ratio, server.robot.rot_ratio, server.robot.throttle) == (0, 0, 0)
        assert server.robot.received_ratios == (0, 60, 100, 0) and server.robot.received_throttle == 100
        await server.advance(1.0)
        assert server.robot.rot_vel == 0 and server.robot.status == "Stopped"
        assert server.robot.mode == "Drive"  # still in ratio drive, as ARIA
        # The next command drives again.
        await _drive(server, c, RatioDrive(0, 60, 100), 0.5)
        assert server.robot.rot_vel > 0
        await _end(server, c)

    run(scenario())


def test_watchdog_timeout_is_configurable(arena_map):
    async def scenario() -> None:
        server, c = await _start(arena_map, drive_timeout=0.5)
        c.once("ratioDrive", RatioDrive(0, 60, 100).encode())
        await c.barrier()
        await server.advance(0.6)
        assert server.robot.watchdog_stops == 1
        await _end(server, c)

    run(scenario())


def test_unsafe_drive_hits_the_box_and_stalls_without_passing_it(arena_map):
    async def scenario() -> None:
        server, c = await _start(arena_map)
        c.once("setSafeDrive", SetSafeDrive(False).encode())
        c.request("updateStrings", -1)
        await _drive(server, c, RatioDrive(60, 0, 100), 6.0)
        # A box spans x 2300..2700 straight ahead; the 250 mm robot must stop at 2050.
        assert server.robot.x <= 2050.5
        assert server.robot.x > 2000
        assert server.robot.collisions >= 1
        assert server.robot.status == "Stalled"
        strings = [UpdateStrings.decode(p) for p in c.received["updateStrings"]]
        assert UpdateStrings("Stalled", "UNSAFE Drive", "Stalled") in strings
        await _end(server, c)

    run(scenario())


def test_safe_drive_slows_and_stops_short_of_the_box(arena_map):
    async def scenario() -> None:
        server, c = await _start(arena_map)
        await _drive(server, c, RatioDrive(100, 0, 100), 8.0)
        assert server.robot.collisions == 0
        assert server.robot.vel == 0
        assert 1900 <= server.robot.x < 2050
        assert server.robot.status == "Stopped"
        await _end(server, c)

    run(scenario())


def test_jog_moves_and_turns_with_arias_status_strings(arena_map):
    async def scenario() -> None:
        server, c = await _start(arena_map)
        c.request("updateStrings", -1)
        c.once("moveDist", MoveDist(300).encode())
        await c.barrier()
        await server.advance(4.0)
        assert abs(server.robot.x - 300) < 5 and server.robot.vel == 0
        assert (server.robot.mode, server.robot.status) == ("Jog", "Moving 300 mm")
        c.once("turnByAngle", TurnByAngle(90).encode())
        await c.barrier()
        await server.advance(4.0)
        assert abs(server.robot.th - 90) < 1.5 and server.robot.rot_vel == 0
        assert server.robot.status == "Turning by 90 deg"
        strings = [UpdateStrings.decode(p).status for p in c.received["updateStrings"]]
        assert "Moving 300 mm" in strings and "Turning by 90 deg" in strings
        await _end(server, c)

    run(scenario())


def test_wander_roams_without_hitting_anything_and_is_deterministic(arena_map):
    async def trip(seed: int) -> tuple[float, float]:
        server, c = await _start(arena_map, seed=seed)
        c.once("wander")
        await c.barrier()
        await server.advance(40.0)
        assert server.robot.mode == "Wander" and server.robot.status == "Wandering"
        assert server.robot.collisions == 0
        pose = (server.robot.x, server.robot.y)
        await _end(server, c)
        return pose

    a = run(trip(3))
    b = run(trip(3))
    assert a == b
    assert a != (0.0, 0.0)


def test_the_other_status_data_answer_as_serverdemo(arena_map):
    from rtmu.protocol.payloads.camera import CameraList
    from rtmu.protocol.payloads.robot import (
        ActivityTimeInfo,
        BatteryInfo,
        ModeDataList,
        PhysicalInfo,
        Update,
    )

    async def scenario() -> None:
        server, c = await _start(arena_map)
        assert BatteryInfo.decode((await c.ask("batteryInfo"))[0]) == BatteryInfo(11.5, 11.0, False)
        assert PhysicalInfo.decode((await c.ask("physicalInfo"))[0]) == PhysicalInfo(
            "Pioneer", "p3dx", 425, 210, 301, False
        )
        update = Update.decode((await c.ask("update"))[0])
        assert (update.status, update.mode, update.numbers.x) == ("Stopped", "Stop", 0)
        rows = ModeDataList.decode((await c.ask("getModeDataList"))[0]).entries
        pairs = {(r.mode_name, r.data_name) for r in rows}
        assert {("ratioDrive", "ratioDrive"), ("stop", "stop"), ("wander", "wander")} <= pairs
        assert ("jogPositionMode", "moveDist") in pairs
        await server.advance(3.0)
        assert ActivityTimeInfo.decode((await c.ask("activityTimeInfo"))[0]).seconds == 3
        cams = CameraList.decode((await c.ask("getCameraList"))[0]).cameras
        assert cams[0].name == "Cam1" and cams[0].data_name("getPicture") == "getPictureCam1"
        assert cams[0].data_name("getVideo") == "sendVideo"
        await _end(server, c)

    run(scenario())

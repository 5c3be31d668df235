"""Mode locks on demand: getModeInfo's lock flags, a drive refused by a lock, stop always taken."""

from __future__ import annotations

from rtmu.package_data import project_map
from rtmu.protocol.payloads.commands import CommandList
from rtmu.protocol.payloads.drive import RatioDrive
from rtmu.protocol.payloads.robot import ModeInfo
from rtmu.sim import SimConfig, SimServer

from .wire import WireClient, run

ARENA = project_map("arena.map")


async def _start() -> tuple[SimServer, WireClient]:
    server = SimServer(SimConfig(port=0, realtime=False, map_path=ARENA))
    await server.start()
    c = await WireClient().open(server.port)
    c.request("getModeInfo", -1)
    await c.wait_for("getModeInfo")
    return server, c


def _last_mode(c: WireClient) -> ModeInfo:
    return ModeInfo.decode(c.received["getModeInfo"][-1])


def test_a_stop_that_will_not_unlock_holds_against_a_drive_and_is_said_so() -> None:
    async def scenario() -> None:
        server, c = await _start()
        names = [e.name for e in CommandList.decode((await c.ask("listCommands"))[0]).commands]
        assert {"SimulatorLockStopMode", "SimulatorLockStopModeUnlockable", "SimulatorUnlockMode"} <= set(
            names
        )
        c.once("SimulatorLockStopMode")
        await c.until(lambda: _last_mode(c).locked)
        assert _last_mode(c) == ModeInfo("stop", True, False)
        for _ in range(10):
            c.once("ratioDrive", RatioDrive(100, 0, 100).encode())
            await server.advance(0.1)
        assert server.robot.mode_name == "stop" and abs(server.robot.vel) < 1
        c.once("stop")  # stop is always taken, and keeps the lock
        await c.barrier()
        assert ModeInfo.decode((await c.ask("getModeInfo"))[0]) == ModeInfo("stop", True, False)
        c.once("SimulatorUnlockMode")
        await c.until(lambda: not _last_mode(c).locked)
        c.once("ratioDrive", RatioDrive(100, 0, 100).encode())
        await server.advance(0.5)
        assert server.robot.mode_name == "ratioDrive" and server.robot.vel > 50
        c.once("stop")
        await c.close()
        await server.stop()

    run(scenario())


def test_a_stop_that_yields_gives_way_to_the_mode_that_asks() -> None:
    async def scenario() -> None:
        server, c = await _start()
        c.once("SimulatorLockStopModeUnlockable")
        await c.until(lambda: _last_mode(c).locked)
        assert _last_mode(c) == ModeInfo("stop", True, True)
        c.once("ratioDrive", RatioDrive(100, 0, 100).encode())
        await server.advance(0.3)
        await c.until(lambda: _last_mode(c).mode_name == "ratioDrive")
        assert _last_mode(c) == ModeInfo("ratioDrive", False, False)
        c.once("stop")
        await c.close()
        await server.stop()

    run(scenario())

"""``rtmu status``, ``doctor``, ``why`` and the window read a status the same way (``client.robot_status``).

Against the simulator as a Pioneer (``updateNumbers`` + ``updateStrings``, volts) and as an LD robot
(the old ``update``, ``batteryInfo`` saying state of charge): the status the CLI prints — once, and
streamed — is the ``RobotState`` the window's status feed publishes for the same standing robot.
"""

from __future__ import annotations

import json

import pytest

from client.uiqueue import UiQueue
from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_OK
from rtmu.cli import main
from rtmu.client.runner import ClientRunner
from rtmu.model.observables import RobotModel
from rtmu.package_data import project_map
from rtmu.sim import SimThread
from rtmu.values.state import RobotState
from rtmu.values.target import Target
from simulators import simulator

OFFICE = project_map("office.map")

pioneer = simulator(scope="module", map_path=OFFICE)
ld = simulator(scope="module", profile="aram", map_path=OFFICE)


def window_reading(sim: SimThread) -> RobotState:
    """The robot's state as the window's session publishes it (status, strings and battery unit in)."""
    model, ui = RobotModel(), UiQueue()
    with ClientRunner(model, post=ui.post) as runner:
        runner.connect(Target("127.0.0.1", sim.port)).result(10)

        def complete() -> bool:
            r = model.robot.value
            known = r.numbers_at is not None and r.strings_at is not None and r.battery_v is not None
            return known and (r.dock_state is not None or not runner.session.client.supports("dockInfo"))  # type: ignore[union-attr]

        ui.wait_for(complete, 10)
        return model.robot.value


def cli_lines(sim: SimThread, *more: str, capsys: pytest.CaptureFixture[str]) -> list[dict[str, object]]:
    assert main(["status", f"127.0.0.1:{sim.port}", "--timeout", cli_timeout(5), "--json", *more]) == EXIT_OK
    return [json.loads(line) for line in capsys.readouterr().out.splitlines()]


@pytest.mark.parametrize("robot", ["pioneer", "ld"])
def test_the_cli_prints_the_status_the_window_reads(
    robot: str, request: pytest.FixtureRequest, capsys: pytest.CaptureFixture[str]
) -> None:
    sim: SimThread = request.getfixturevalue(robot)
    seen = window_reading(sim)
    battery = "battery_pct" if seen.battery_is_soc else "battery_v"
    assert seen.battery_is_soc is (robot == "ld")  # the LD robot's figure is a state of charge
    once = cli_lines(sim, "--once", capsys=capsys)
    streamed = cli_lines(sim, "--count", "2", "--interval", "50", capsys=capsys)
    for obj in [*once, *streamed]:
        assert (obj["x"], obj["y"], obj["th"]) == (seen.x, seen.y, seen.th)  # a standing robot
        assert (obj["vel"], obj["rot_vel"]) == (seen.vel, seen.rot_vel) == (0, 0)
        assert obj["status"] == seen.status and obj["mode"] == seen.mode and seen.status
        dock = {"dock"} if robot == "ld" else set()  # an LD robot's dockInfo, as the window shows it
        assert set(obj) == {"x", "y", "th", "vel", "rot_vel", battery, "status", "mode", *dock}
        assert obj.get("dock") == (seen.dock_state if dock else None)
        assert obj[battery] == pytest.approx(seen.battery_v, abs=0.5)  # the simulated battery drains
        assert all(isinstance(obj[k], int) for k in ("x", "y", "th"))  # the wire's whole numbers stay whole


@pytest.mark.parametrize("robot", ["pioneer", "ld"])
def test_doctor_and_why_read_the_status_the_window_reads(
    robot: str, request: pytest.FixtureRequest, capsys: pytest.CaptureFixture[str]
) -> None:
    """``rtmu doctor``'s status step and ``rtmu why``'s facts take the same reading
    (``robot_status.read_status``): the same pose, words and battery figure in the same unit."""
    import asyncio

    from rtmu.client.connection import AriaClient
    from rtmu.client.why_gather import gather
    from rtmu.client.why_values import Facts

    sim: SimThread = request.getfixturevalue(robot)
    seen = window_reading(sim)
    assert main(["doctor", f"127.0.0.1:{sim.port}", "--timeout", cli_timeout(5), "--json"]) == EXIT_OK
    report = json.loads(capsys.readouterr().out)
    step = next(s for s in report["steps"] if s["step"] == "status")
    assert (step["x"], step["y"], step["th"], step["status"]) == (seen.x, seen.y, seen.th, seen.status)
    battery = "battery_pct" if seen.battery_is_soc else "battery_v"
    assert step[battery] == pytest.approx(seen.battery_v, abs=0.5)

    async def facts() -> Facts:
        client = AriaClient()
        await client.connect(Target("127.0.0.1", sim.port), timeout=5)
        try:
            return await gather(client, 5)
        finally:
            await client.disconnect()

    why = asyncio.run(facts())
    assert (why.status, why.mode, why.vel, why.rot_vel) == (seen.status, seen.mode, 0, 0)
    assert why.battery_soc is seen.battery_is_soc
    assert why.battery == pytest.approx(seen.battery_v, abs=0.5)

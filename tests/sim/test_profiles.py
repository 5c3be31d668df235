"""``rtmu sim --kind aram``: an LD robot on the wire (protocol, state of charge, Ex4 map, 6MTX data)."""

from __future__ import annotations

import asyncio
from pathlib import Path

import pytest

from rtmu.client.connection import AriaClient
from rtmu.package_data import project_map
from rtmu.protocol.payloads.commands import CommandList
from rtmu.protocol.payloads.robot import BatteryInfo, UpdateNumbers
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.ld_data import CONFIG_API
from rtmu.sim.profiles import ARAM, DEFAULT, EX4_HEADER, NOT_LISTED_BY_6MTX, get_profile
from rtmu.values.target import Target
from simulators import simulator

OFFICE = project_map("office.map")


aram = simulator(scope="module", profile="aram", map_path=OFFICE)


async def _with_client(port: int, body):  # type: ignore[no-untyped-def]
    client = AriaClient()
    await client.connect(Target("127.0.0.1", port), timeout=5.0)
    try:
        return await body(client)
    finally:
        await client.disconnect()


def test_unknown_profile_is_refused() -> None:
    with pytest.raises(ValueError, match="no simulator profile"):
        get_profile("nope")


def test_catalogue_lists_only_what_6mtx_robots_list(aram: SimThread) -> None:
    async def body(client: AriaClient):  # type: ignore[no-untyped-def]
        commands = CommandList.decode((await client.request_once("listCommands", timeout=5)).payload)
        return list(client.datalist), [c.name for c in commands.commands]

    entries, commands = asyncio.run(_with_client(aram.port, body))
    names = [e.name for e in entries]
    assert len(names) == len(set(names))
    assert not set(names) & NOT_LISTED_BY_6MTX
    assert {"ratioDrive", "stop", "updateNumbers", "getMapBinary", "dockInfo", "configUpdated"} <= set(names)
    # LD's configuration API instead of ArConfig's; no camera; none of the simulator's own commands.
    assert {row[0] for row in CONFIG_API} <= set(names)
    assert not any(n.startswith(("getConfigBySections", "getPicture", "Simulator")) for n in names)
    assert "setConfig" not in names and "sendVideo" not in names
    assert commands == ["ResetTripOdometer"]  # listCommands names only listed data
    # What is left out is left out of the aram profile only: the default one still lists all of it.
    default = {e.name for e in DEFAULT.catalogue(camera=True)}
    assert default >= NOT_LISTED_BY_6MTX  # and every name left out is one the simulator has (no typo)


def test_battery_is_state_of_charge(aram: SimThread) -> None:
    async def body(client: AriaClient):  # type: ignore[no-untyped-def]
        info = (await client.request_once("batteryInfo", timeout=5)).decode()
        numbers = (await client.request_once("updateNumbers", timeout=5)).decode()
        return info, numbers

    server = aram.server
    assert server is not None
    aram.call(lambda: setattr(server.world.body, "battery_v", 12.366))  # 76 % of 11.0…12.8 V
    info, numbers = asyncio.run(_with_client(aram.port, body))
    assert isinstance(info, BatteryInfo) and info.state_of_charge is True
    assert isinstance(numbers, UpdateNumbers)
    assert numbers.battery == pytest.approx(75.9, abs=0.2)


def test_map_served_as_ex4_text_and_binary(aram: SimThread) -> None:
    async def body(client: AriaClient):  # type: ignore[no-untyped-def]
        text = [p async for p in client.stream("getMap", timeout=5)]
        binary = [p async for p in client.stream("getMapBinary", timeout=5)]
        return text, binary

    text, binary = asyncio.run(_with_client(aram.port, body))
    assert text[0] == EX4_HEADER.encode() + b"\x00"
    assert binary[0] == EX4_HEADER.encode() + b"\x00"
    assert OFFICE.read_text().startswith("2D-Map\n")  # the file itself stays ours, unchanged


def test_default_profile_is_unchanged() -> None:
    with SimThread(SimConfig(port=0)) as sim:
        assert sim.server is not None
        assert sim.server.profile.name == "default"
        assert len(list(sim.server.datalist)) < 200
        assert sim.server.config.protocol_version is None


def test_modules_extend_a_profile(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    mod = tmp_path / "h8a_probe_data.py"
    mod.write_text(
        "ROWS = (('sayHello', 'Says hello', 'none', 'none', 'Audio', 'RETURN_SINGLE'),)\n"
        "def _hello(call):\n    return (b'hi\\x00',)\n"
        "HANDLERS = {'sayHello': _hello}\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    from dataclasses import replace

    profile = replace(ARAM, modules=("h8a_probe_data",))
    assert "sayHello" in profile.catalogue(camera=True)
    assert profile.handler_table()["sayHello"].__name__ == "_hello"


def test_deprecated_update_also_reports_state_of_charge(aram: SimThread) -> None:
    from rtmu.protocol.payloads.robot import Update

    async def body(client: AriaClient):  # type: ignore[no-untyped-def]
        return (await client.request_once("update", timeout=5)).decode()

    update = asyncio.run(_with_client(aram.port, body))
    assert isinstance(update, Update) and 0.0 <= update.numbers.battery <= 100.0


def test_robot_state_battery_pct_follows_the_flag() -> None:
    from rtmu.model.observables import RobotState

    assert RobotState(battery_v=87.0, battery_is_soc=True).battery_pct == 87.0
    assert RobotState(battery_v=12.8).battery_pct is None

"""``rtmu routes / patrol / say / status`` against ``rtmu sim --kind aram`` and the default profile."""

from __future__ import annotations

import asyncio
import json

import pytest

from client.uiqueue import eventually
from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_OK, EXIT_UNSUPPORTED, EXIT_USAGE
from rtmu.cli import main
from rtmu.client import ld_data
from rtmu.client.connection import AriaClient
from rtmu.package_data import project_map
from rtmu.sim import SimThread
from rtmu.sim.ld_data import ROUTES, ld_state
from rtmu.values.target import Target
from simulators import simulator

OFFICE = project_map("office.map")


aram = simulator(scope="module", profile="aram", map_path=OFFICE)


plain = simulator(scope="module", map_path=OFFICE)


def addr(sim: SimThread) -> str:
    return f"127.0.0.1:{sim.port}"


def _state(sim: SimThread):  # type: ignore[no-untyped-def]
    assert sim.server is not None
    return sim.call(lambda: ld_state(sim.server))  # type: ignore[arg-type]


def test_routes_lists_the_servers_routes(aram: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["routes", addr(aram), "--timeout", cli_timeout(5)]) == EXIT_OK
    assert capsys.readouterr().out.splitlines() == list(ROUTES)
    assert main(["routes", addr(aram), "--json", "--timeout", cli_timeout(5)]) == EXIT_OK
    assert json.loads(capsys.readouterr().out) == list(ROUTES)


def test_patrol_sends_the_route_and_refuses_an_unknown_one(
    aram: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    before = len(_state(aram).patrols)
    assert main(["patrol", addr(aram), ROUTES[2], "--timeout", cli_timeout(5)]) == EXIT_OK
    eventually(lambda: _state(aram).patrols[before:] == [ROUTES[2]])
    assert main(["patrol", addr(aram), "Nowhere", "--timeout", cli_timeout(5)]) == EXIT_USAGE
    assert "no route 'Nowhere'" in capsys.readouterr().err
    assert _state(aram).patrols[before:] == [ROUTES[2]]


def test_goto_sends_a_route_goal_and_refuses_an_unknown_one(
    aram: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    before = len(_state(aram).route_goals)
    # The aram profile lists ARNL's gotoGoal too: --route asks for the LD command by name.
    assert main(["goto", addr(aram), "Lab A", "--route", "--timeout", cli_timeout(5)]) == EXIT_OK
    eventually(lambda: _state(aram).route_goals[before:] == ["Lab A"])
    assert main(["goto", addr(aram), "Nowhere", "--route", "--timeout", cli_timeout(5)]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert "no goal 'Nowhere'" in err and "Lab A" in err
    assert _state(aram).route_goals[before:] == ["Lab A"]


def test_data_store_values_become_toolbar_fields() -> None:
    # The localization score and the distance left are navigation's, on ARNL's scale (0–1)
    # The names 6MTX robots list …
    assert ld_data.store_fields("DataStore_LaserLocalizationScore", "87.4") == {"loc_score": 0.874}
    assert ld_data.store_fields("DataStore_WirelessQuality", "35", "(0-70)") == {"wifi_quality": 50}
    assert ld_data.store_fields("DataStore_Distance_to_goal", "12400") == {"remaining_mm": 12400}
    assert ld_data.store_fields("DataStore_Closest_Obstacle_Distance", "800") == {"closest_obstacle_mm": 800}
    assert ld_data.store_fields("DataStore_DockingState", "Docked") == {}
    # … and other spellings of the same values.
    assert ld_data.store_fields("DataStore_Localization_Score", "87.4") == {"loc_score": 0.874}
    assert ld_data.store_fields("DataStore_WiFi_Quality", "35", "Wi-Fi link quality (0–70)") == {
        "wifi_quality": 50
    }
    assert ld_data.store_fields("DataStore_WiFi_Quality", "35") == {"wifi_quality": 35}
    assert ld_data.store_fields("DataStore_Distance_To_Goal", "12400") == {"remaining_mm": 12400}
    assert ld_data.store_fields("DataStore_Closest_Obstacle", "none") == {"closest_obstacle_mm": None}
    assert ld_data.store_fields("DataStore_Dock_State", "Docked") == {}
    assert ld_data.store_fields("DataStore_Distance_to_goal", "0") == {"remaining_mm": None}  # 0: no goal
    assert ld_data.store_fields("DataStore_LaserLocalizationScore", "130") == {"loc_score": 1.0}


def test_say_sends_the_text(aram: SimThread) -> None:
    assert main(["say", addr(aram), "Mind the gap", "--timeout", cli_timeout(5)]) == EXIT_OK
    eventually(lambda: "Mind the gap" in _state(aram).said)
    assert main(["say", addr(aram), "   ", "--timeout", cli_timeout(5)]) == EXIT_USAGE


def test_status_says_the_dock_state(aram: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["status", addr(aram), "--once", "--json", "--timeout", cli_timeout(5)]) == EXIT_OK
    assert json.loads(capsys.readouterr().out)["dock"] == "Undocked"
    assert main(["status", addr(aram), "--once", "--timeout", cli_timeout(5)]) == EXIT_OK
    assert "dock=Undocked" in capsys.readouterr().out


def test_data_store_strings_are_read_by_name(aram: SimThread) -> None:
    async def go() -> dict[str, str]:
        client = AriaClient()
        await client.connect(Target("127.0.0.1", aram.port), timeout=5.0)
        try:
            return await ld_data.data_store(client, 5.0)
        finally:
            await client.disconnect()

    values = asyncio.run(go())
    assert set(values) >= {
        "DataStore_WirelessQuality",
        "DataStore_LaserLocalizationScore",
        "DataStore_DockingState",
    }
    assert 0 <= int(values["DataStore_WirelessQuality"]) <= 70


def test_default_profile_offers_none_of_it(plain: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["routes", addr(plain), "--timeout", cli_timeout(5)]) == EXIT_UNSUPPORTED
    assert main(["patrol", addr(plain), "Loop", "--timeout", cli_timeout(5)]) == EXIT_UNSUPPORTED
    assert main(["say", addr(plain), "hello", "--timeout", cli_timeout(5)]) == EXIT_UNSUPPORTED
    assert main(["goto", addr(plain), "Lab A", "--route", "--timeout", cli_timeout(5)]) == EXIT_UNSUPPORTED
    capsys.readouterr()
    assert main(["status", addr(plain), "--once", "--json", "--timeout", cli_timeout(5)]) == EXIT_OK
    assert "dock" not in json.loads(capsys.readouterr().out)

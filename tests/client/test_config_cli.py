"""``rtmu config`` against the simulator: list, JSON, set, refusals (exit 6), no configuration (exit 4)."""

from __future__ import annotations

import json
from collections.abc import Iterator

import pytest

from rtmu.cli import main
from rtmu.exit_codes import EXIT_OK, EXIT_UNSUPPORTED, EXIT_USAGE
from rtmu.sim import SimConfig, SimThread
from rtmu.subcommands.config import EXIT_REFUSED

from .servers import ServerThread, TestServer


@pytest.fixture
def sim() -> Iterator[SimThread]:
    with SimThread(SimConfig(port=0)) as s:
        yield s


def addr(port: int) -> str:
    return f"127.0.0.1:{port}"


def test_config_lists_sections_and_parameters(sim: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["config", addr(sim.port), "--timeout", "5"]) == EXIT_OK
    out = capsys.readouterr().out
    assert "[Teleop]" in out and "Timeout = 2    [double 0…60, intermediate]" in out
    assert "FrameSize = 320x240    [string one of 320x240, 640x480, intermediate]" in out
    assert "SerialNumber = SIM-P3DX-0001    [string, factory, read-only]" in out


def test_config_json_has_types_limits_and_editability(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["config", addr(sim.port), "--json", "--timeout", "5"]) == EXIT_OK
    doc = json.loads(capsys.readouterr().out)
    assert doc["source"] == "getConfigBySectionsV4" and doc["last_editable"] == "expert"
    params = {f"{s['name']}/{p['name']}": p for s in doc["sections"] for p in s["params"]}
    assert params["Teleop/Timeout"] | {"description": ""} == {
        "name": "Timeout",
        "type": "double",
        "value": 2.0,
        "description": "",
        "priority": "intermediate",
        "editable": True,
        "min": 0.0,
        "max": 60.0,
    }
    assert params["Camera/FrameSize"]["choices"] == ["320x240", "640x480"]
    assert params["Robot config/SerialNumber"]["editable"] is False
    assert params["Battery/Drain"]["value"] is True


def test_config_set_changes_the_simulation(sim: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(
        [
            "config",
            addr(sim.port),
            "--timeout",
            "5",
            "--set",
            "Teleop/Timeout=0.75",
            "Robot config/TransVelMax=400",
        ]
    )
    assert code == EXIT_OK
    assert capsys.readouterr().out.strip() == "accepted: 2 values"
    assert sim.call(
        lambda: (sim.server.world.ratio_mode.timeout, sim.server.world.ratio_mode.trans_vel_max)
    ) == (
        0.75,
        400,
    )
    assert main(["config", addr(sim.port), "--json", "--timeout", "5"]) == EXIT_OK
    doc = json.loads(capsys.readouterr().out)
    assert doc["sections"][0]["params"][0]["value"] == 0.75


def test_a_refused_value_exits_6_with_the_servers_words(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        ["config", addr(sim.port), "--timeout", "5", "--set", "Teleop/Timeout=1", "Camera/FrameSize=1x1"]
    )
    assert code == EXIT_REFUSED
    err = capsys.readouterr().err
    assert (
        err.strip()
        == "rtmu config: the server refused: Camera/FrameSize: '1x1' is not one of 320x240, 640x480"
    )
    assert sim.call(lambda: sim.server.world.ratio_mode.timeout) == 2.0  # all or nothing
    code = main(["config", addr(sim.port), "--json", "--timeout", "5", "--set", "Teleop/Timeout=-1"])
    assert code == EXIT_REFUSED
    assert json.loads(capsys.readouterr().out) == {
        "accepted": False,
        "error": "Teleop/Timeout: -1 is below the minimum of 0",
    }


def test_markup_and_control_characters_from_the_server_are_printed_harmlessly(
    capsys: pytest.CaptureFixture[str],
) -> None:
    with SimThread(SimConfig(port=0, config_filler=40)) as s:
        assert main(["config", addr(s.port), "--timeout", "5"]) == EXIT_OK
    out = capsys.readouterr().out
    assert "[<b>Extra</b> & 0]" in out and "P1<i>&amp; = 0.1" in out  # literal, as the server sent it


def test_bad_assignments_fail_before_connecting(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["config", "127.0.0.1:9", "--set", "NoSlash=1"])
    assert exit_info.value.code == EXIT_USAGE
    assert "SECTION/PARAM=VALUE" in capsys.readouterr().err


def test_a_server_without_configuration_exits_4(capsys: pytest.CaptureFixture[str]) -> None:
    with ServerThread(TestServer()) as server:
        assert main(["config", addr(server.port), "--timeout", "5"]) == EXIT_UNSUPPORTED
        assert "offers no configuration" in capsys.readouterr().err
        assert main(["config", addr(server.port), "--timeout", "5", "--set", "A/b=1"]) == EXIT_UNSUPPORTED

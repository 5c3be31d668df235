"""``rtmu commands / run / watch`` against the simulator, and ``run`` against a server that stays silent."""

from __future__ import annotations

import json
import threading
import time

import pytest

from client.servers import SPECS, ServerThread, TestServer
from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_OK, EXIT_TIMEOUT, EXIT_UNSUPPORTED, EXIT_USAGE
from rtmu.cli import main
from rtmu.client.health import PING_CANDIDATES
from rtmu.protocol.payloads.commands import CommandEntry, CommandList
from rtmu.sim import SimThread
from simulators import simulator

sim = simulator(scope="module")


def addr(port: int) -> str:
    return f"127.0.0.1:{port}"


def test_commands_lists_names_descriptions_and_which_take_an_argument(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["commands", addr(sim.port), "--timeout", cli_timeout(5)]) == EXIT_OK
    lines = capsys.readouterr().out.splitlines()
    battery = next(line for line in lines if line.startswith("SimulatorSetBattery"))
    assert " ARG " in battery and "battery voltage" in battery
    reset = next(line for line in lines if line.startswith("ResetTripOdometer"))
    assert " ARG " not in reset
    assert main(["commands", addr(sim.port), "--json", "--timeout", cli_timeout(5)]) == EXIT_OK
    listed = {c["name"]: c for c in json.loads(capsys.readouterr().out)}
    assert listed["SimulatorSetBattery"]["argument"] is True
    assert listed["ResetTripOdometer"] == {
        "name": "ResetTripOdometer", "description": "Resets the robot's trip odometer", "argument": False,
    }  # fmt: skip


def test_run_sends_a_string_command_and_says_it_was_taken(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    assert (
        main(["run", addr(sim.port), "SimulatorSetBattery", "12.25", "--timeout", cli_timeout(5)]) == EXIT_OK
    )
    assert "taken by the server" in capsys.readouterr().out
    assert sim.call(lambda: sim.server.world.body.battery_v) == pytest.approx(12.25)  # type: ignore[union-attr]
    assert (
        main(["run", addr(sim.port), "SimulatorRecharge", "--json", "--timeout", cli_timeout(5)]) == EXIT_OK
    )
    ran = json.loads(capsys.readouterr().out)
    assert ran == {"command": "SimulatorRecharge", "argument": None, "taken": True}


def test_run_refuses_unknown_names_and_wrong_arguments(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["run", addr(sim.port), "Nope\x1b[2J", "--timeout", cli_timeout(5)]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert "no command" in err and "\x1b" not in err and "\\x1b" in err
    assert main(["run", addr(sim.port), "SimulatorSetBattery", "--timeout", cli_timeout(5)]) == EXIT_USAGE
    assert "takes an argument" in capsys.readouterr().err
    assert main(["run", addr(sim.port), "SimulatorRecharge", "x", "--timeout", cli_timeout(5)]) == EXIT_USAGE
    assert "takes no argument" in capsys.readouterr().err


def test_run_exits_5_when_the_server_stays_silent(capsys: pytest.CaptureFixture[str]) -> None:
    specs = [
        *SPECS,
        ("listCommands", "list", "none", "list", "CustomCommands", "RETURN_SINGLE"),
        ("Hang", "a command", "none", "none", "CustomCommands", "RETURN_NONE"),
    ]
    server = TestServer(specs)
    server.handlers["listCommands"] = lambda s, a: [CommandList((CommandEntry("Hang", "hangs"),)).encode()]
    for name in PING_CANDIDATES:  # the request behind the command gets no answer
        server.handlers[name] = lambda s, a: []
    with ServerThread(server) as srv:
        assert main(["run", addr(srv.port), "Hang", "--timeout", "0.5"]) == EXIT_TIMEOUT
        assert "did not answer" in capsys.readouterr().err
        assert [r.name for r in srv.received if r.name == "Hang"] == ["Hang"]


def test_commands_exits_4_where_the_server_lists_none(capsys: pytest.CaptureFixture[str]) -> None:
    with ServerThread(TestServer()) as srv:
        assert main(["commands", addr(srv.port), "--timeout", cli_timeout(5)]) == EXIT_UNSUPPORTED


def test_watch_prints_popups_mode_and_status_as_they_happen(
    sim: SimThread, capsys: pytest.CaptureFixture[str]
) -> None:
    world = sim.server.world  # type: ignore[union-attr]
    sim.call(lambda: world.create_popup("Open <b>already</b>", "before watch", buttons=("OK", "", "")))

    def later() -> None:
        time.sleep(0.8)
        sim.call(lambda: world.create_popup("New\x1b]0;x\x07", "during & watch", kind=2, timeout=0.3))

    helper = threading.Thread(target=later)
    helper.start()
    try:
        assert (
            main(["watch", addr(sim.port), "--json", "--seconds", "2.5", "--timeout", cli_timeout(5)])
            == EXIT_OK
        )
    finally:
        helper.join()
    out = capsys.readouterr().out
    events = [json.loads(line) for line in out.splitlines()]
    kinds = [e["event"] for e in events]
    assert "mode" in kinds and "status" in kinds
    opened = [e for e in events if e["event"] == "popup_opened"]
    assert [e["title"] for e in opened][:2] == ["Open <b>already</b>", "New\x1b]0;x\x07"]
    assert "\x1b" not in out  # exact in JSON, yet inert on a terminal
    closed = [e for e in events if e["event"] == "popup_closed"]
    assert closed and closed[0]["id"] == opened[1]["id"] and closed[0]["message"] == "No answer"
    assert all(e["t"] >= 0 for e in events)


def test_watch_text_lines_escape_server_text(sim: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    world = sim.server.world  # type: ignore[union-attr]
    sim.call(lambda: world.create_popup("Bell\x07", "x", buttons=("OK", "", "")))
    assert main(["watch", addr(sim.port), "--seconds", "0.5", "--timeout", cli_timeout(5)]) == EXIT_OK
    out = capsys.readouterr().out
    assert "popup opened" in out and "Bell\\x07" in out and "\x07" not in out

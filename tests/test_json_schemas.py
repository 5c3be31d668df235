"""Every ``--json`` line a subcommand prints follows its published schema (``subcommands.json_schemas``).

Each command runs for real against the simulator (an LD ``aram`` one: it offers routes, docking and
a camera head) or a central server, and every line of its output is checked with the reference
validator; the navigation commands also end by a limit and by Ctrl-C, whose last lines are part
of the promise.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import jsonschema
import pytest

from rtmu.cli import build_parser
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.central_thread import CentralThread
from rtmu.subcommands.json_schemas import COMMAND_SCHEMA, SCHEMAS

REPO = Path(__file__).resolve().parents[1]
OFFICE = REPO / "data" / "maps" / "office.map"
RTMU = [sys.executable, "-m", "rtmu"]

RUNS: list[tuple[str, list[str]]] = [
    ("status", ["--once"]),
    ("status", ["--count", "2"]),
    ("goals", []),
    ("routes", []),
    ("probe", []),
    ("commands", []),
    ("config", []),
    ("config", ["--set", "Teleop/Timeout=-1"]),
    ("drawings", []),
    ("watch", ["--seconds", "1"]),
    ("ptz", []),
    ("video", ["--seconds", "1"]),
    ("doctor", []),
    ("drive", ["--trans", "30", "--seconds", "0.3"]),
    ("run", ["ResetTripOdometer"]),
    ("localize", ["2000", "6000", "0"]),
    ("localize", ["2000", "6000", "0", "--no-wait"]),
    ("goto", ["Room 101", "--limit", "2"]),
    ("goto", ["Room 101", "--no-wait"]),
    ("home", ["--limit", "60"]),
    ("dock", ["--limit", "60"]),
]


@pytest.fixture(scope="module")
def sim() -> Iterator[SimThread]:
    with SimThread(SimConfig(port=0, map_path=OFFICE, profile="aram")) as s:
        yield s


def check_lines(name: str, stdout: str) -> int:
    schema = SCHEMAS[COMMAND_SCHEMA[name]]
    lines = [line for line in stdout.splitlines() if line.strip()]
    for line in lines:
        jsonschema.validate(json.loads(line), schema)  # raises with the path of what does not fit
    return len(lines)


def test_every_json_option_has_a_published_schema_that_is_valid() -> None:
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "subcommand")
    with_json = {
        name
        for name, p in sub.choices.items()  # type: ignore[attr-defined]
        if any("--json" in a.option_strings for a in p._actions)
    }
    assert with_json - {"decode", "mapinfo"} <= set(COMMAND_SCHEMA), "a --json without a published schema"
    for schema in SCHEMAS.values():
        jsonschema.Draft202012Validator.check_schema(schema)


@pytest.mark.parametrize(("name", "argv"), RUNS, ids=[f"{n} {' '.join(a)}" for n, a in RUNS])
def test_json_lines_follow_their_schema(sim: SimThread, name: str, argv: list[str]) -> None:
    done = subprocess.run(
        [*RTMU, name, f"127.0.0.1:{sim.port}", *argv, "--json", "--timeout", "5"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert check_lines(name, done.stdout) >= 1, done.stderr


def test_an_interrupted_navigation_ends_with_its_outcome_line(sim: SimThread) -> None:
    proc = subprocess.Popen(
        [*RTMU, "goto", f"127.0.0.1:{sim.port}", "Corridor End", "--json", "--timeout", "5"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout is not None
    first = ""
    for _ in range(10):  # until {"status": "Going to Corridor End", ...}: it is on its way
        first += proc.stdout.readline()
        if "Going to" in first:
            break
    assert "Going to" in first, first
    time.sleep(0.3)
    proc.send_signal(signal.SIGINT)
    rest, _err = proc.communicate(timeout=30)
    assert proc.returncode == 128 + signal.SIGINT
    check_lines("goto", first + rest)
    last = json.loads(rest.splitlines()[-1])
    assert last["outcome"] == "interrupted" and last["signal"] == "SIGINT" and last["x"] is not None


def test_fleet_json_follows_its_schema() -> None:
    with CentralThread(robots=2) as fleet:
        done = subprocess.run(
            [*RTMU, "fleet", f"127.0.0.1:{fleet.port}", "--json", "--timeout", "5"],
            capture_output=True,
            text=True,
            timeout=60,
        )
    assert done.returncode == 0, done.stderr
    assert check_lines("fleet", done.stdout) == 1

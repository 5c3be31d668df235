"""Every ``--json`` line a subcommand prints follows its published schema (``subcommands.json_schemas``).

Each command runs for real against the simulator — an LD ``aram`` one (routes, LD docking, a
configuration RTMU cannot edit yet) and an ARIA one (a camera, ``home``, ArConfig and its factory
values, loop tags while scanning) — or a central server, and every line of its output is checked
with the reference validator. A command that prints several kinds of line runs each kind: the
navigation commands also end by a limit and by Ctrl-C, files / scan / mapedit / config's care run a
round trip on a simulator of their own, a drive that did not move prints its answer.
"""

from __future__ import annotations

import argparse
import json
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import jsonschema
import pytest

from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_REFUSED, EXIT_WHY_NO_DRIVE
from rtmu.cli import actions_of, build_parser
from rtmu.package_data import project_map
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.central_thread import CentralThread
from rtmu.subcommands.json_schemas import COMMAND_SCHEMA, SCHEMAS
from simulators import running

REPO = Path(__file__).resolve().parents[1]
OFFICE = project_map("office.map")
RTMU = [sys.executable, "-m", "rtmu"]

RUNS: list[tuple[str, str, list[str]]] = [
    ("aram", "status", ["--once"]),
    ("aram", "status", ["--count", "2"]),
    ("aram", "goals", []),
    ("aram", "routes", []),
    ("aram", "probe", []),
    ("aram", "commands", []),
    ("aram", "config", []),  # an LD robot's configuration: named, not shown (exit 18)
    ("aram", "config", ["--set", "Teleop/Timeout=-1"]),
    ("aria", "config", []),
    ("aria", "config", ["--set", "Teleop/Timeout=-1"]),  # refused, in the server's words
    ("aria", "config", ["--defaults"]),
    ("aram", "drawings", []),
    ("aram", "watch", ["--seconds", "1"]),
    ("aram", "ptz", []),
    ("aria", "ptz", []),
    ("aria", "video", ["--seconds", "1"]),
    ("aram", "doctor", []),
    ("aram", "drive", ["--trans", "30", "--seconds", "0.3"]),
    ("aria", "drive", ["--trans", "5", "--seconds", "0.3"]),  # inside the dead zone: did not move, and why
    ("aram", "run", ["ResetTripOdometer"]),
    ("aram", "localize", ["2000", "6000", "0"]),
    ("aram", "localize", ["2000", "6000", "0", "--no-wait"]),
    ("aram", "goto", ["Room 101", "--limit", "2"]),
    ("aram", "goto", ["Room 101", "--no-wait"]),
    ("aria", "home", ["--limit", "60"]),
    ("aram", "dock", ["--limit", "60"]),
    ("aram", "why", []),
    ("aria", "why", ["--navigate"]),
    ("aram", "call", ["updateNumbers"]),
    ("aram", "call", ["--list", "config"]),
    ("aram", "call", ["getConfigValues"]),  # a layout RTMU does not know: bytes and guessed fields
    ("aria", "call", ["updateNumbers", "--every", "100", "--seconds", "0.5"]),
    ("aram", "files", ["ls"]),
    ("aram", "scan", ["status"]),
    ("aram", "mapedit", ["--check-map"]),
]
"""(simulator, command, arguments): the read-only runs; those that change something have tests below."""


@pytest.fixture(scope="module")
def sims() -> Iterator[dict[str, SimThread]]:
    with (
        running(map_path=OFFICE, profile="aram") as aram,
        running(map_path=OFFICE) as aria,
    ):
        yield {"aram": aram, "aria": aria}


def rtmu(sim: SimThread, name: str, *argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*RTMU, name, f"127.0.0.1:{sim.port}", *argv, "--json", "--timeout", cli_timeout(5)],
        capture_output=True,
        text=True,
        timeout=120,
    )


def check_lines(name: str, stdout: str) -> int:
    schema = SCHEMAS[COMMAND_SCHEMA[name]]
    lines = [line for line in stdout.splitlines() if line.strip()]
    for line in lines:
        jsonschema.validate(json.loads(line), schema)  # raises with the path of what does not fit
    return len(lines)


def has_json(parser: argparse.ArgumentParser) -> bool:
    """``--json`` on the subcommand or on one of its action words (``rtmu files HOST ls --json``)."""
    return any("--json" in a.option_strings for a in parser._actions) or any(
        has_json(p) for p in actions_of(parser)
    )


def test_every_json_option_has_a_published_schema_that_is_valid() -> None:
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "subcommand")
    with_json = {name for name, p in sub.choices.items() if has_json(p)}  # type: ignore[attr-defined]
    assert {"files", "scan", "why", "call"} <= with_json, "action words' --json are seen"
    assert with_json - {"decode", "mapinfo"} <= set(COMMAND_SCHEMA), "a --json without a published schema"
    assert set(COMMAND_SCHEMA) <= with_json, "a schema for a command without --json"
    for schema in SCHEMAS.values():
        jsonschema.Draft202012Validator.check_schema(schema)


def test_a_schema_tells_one_kind_of_line_from_another() -> None:
    """oneOf means exactly one: a line that fits two kinds (or none) is refused, so the kinds stay apart."""
    config = SCHEMAS[COMMAND_SCHEMA["config"]]
    jsonschema.validate({"accepted": False, "error": "Timeout: below its minimum"}, config)
    jsonschema.validate({"accepted": True, "sent": 0, "unchanged": 3}, config)  # --import, nothing to send
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate({"accepted": True}, config)  # neither --set's answer nor --import's
    with pytest.raises(jsonschema.ValidationError):  # a new key must be published first
        jsonschema.validate({"reloaded": True, "seconds": 1}, config)
    scan = SCHEMAS[COMMAND_SCHEMA["scan"]]
    jsonschema.validate({"scanning": True, "file": "office.2d"}, scan)  # start
    jsonschema.validate({"scanning": True, "name": "Office", "file": "office.2d"}, scan)  # status
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate({"scanning": False, "file": "office.2d"}, scan)  # start says true


@pytest.mark.parametrize(("kind", "name", "argv"), RUNS, ids=[f"{k} {n} {' '.join(a)}" for k, n, a in RUNS])
def test_json_lines_follow_their_schema(
    sims: dict[str, SimThread], kind: str, name: str, argv: list[str]
) -> None:
    done = rtmu(sims[kind], name, *argv)
    assert check_lines(name, done.stdout) >= 1, done.stderr


def test_a_drive_that_may_not_drive_prints_no_poses_and_why(tmp_path: Path) -> None:
    users = tmp_path / "users"
    users.write_text("UserInfoVersion1\nuser viewer pw RobotInfo SensorInfo Stop\n")
    (tmp_path / "pw").write_text("pw\n")
    login = ["--user", "viewer", "--password-file", str(tmp_path / "pw")]
    with SimThread(SimConfig(port=0, map_path=OFFICE, users_path=users)) as sim:
        done = rtmu(sim, "drive", "--trans", "50", "--seconds", "0.3", *login)
    assert done.returncode == EXIT_WHY_NO_DRIVE, done.stderr
    assert check_lines("drive", done.stdout) == 1
    line = json.loads(done.stdout)
    assert line["before"] is None and line["moved"] is False and line["why"]["cause"] == "no_drive"


def run_all(sim: SimThread, name: str, runs: list[list[str]]) -> str:
    """Each command line in turn (each must succeed); every line they print, for one schema."""
    out = ""
    for argv in runs:
        done = rtmu(sim, name, *argv)
        assert done.returncode == 0, (argv, done.stderr)
        out += done.stdout
    return out


def test_files_round_trip_lines(tmp_path: Path) -> None:
    local = tmp_path / "note.txt"
    local.write_text("a file the robot keeps\n")
    with SimThread(SimConfig(port=0, map_path=OFFICE)) as sim:
        out = run_all(
            sim,
            "files",
            [
                ["put", str(local), "note.txt"],
                ["ls"],
                ["get", "note.txt", "--out", str(tmp_path / "back.txt")],
                ["rm", "note.txt", "--yes"],
            ],
        )
    assert check_lines("files", out) == 4
    assert (tmp_path / "back.txt").read_text() == local.read_text()


def test_scan_lines_from_start_to_download(tmp_path: Path) -> None:
    with SimThread(SimConfig(port=0, map_path=OFFICE)) as sim:
        out = run_all(
            sim,
            "scan",
            [
                ["start", "Schema"],
                ["status"],
                ["loop", "start"],
                ["loop", "end"],
                ["stop", "--download", str(tmp_path)],
            ],
        )
    assert check_lines("scan", out) == 5
    assert json.loads(out.splitlines()[-1])["downloaded"] == str(tmp_path / "schema.2d")


def test_mapedit_lines_of_a_change_and_its_undoing() -> None:
    with SimThread(SimConfig(port=0, map_path=OFFICE)) as sim:
        out = run_all(
            sim,
            "mapedit",
            [["--add-goal", "Schema Probe", "--x", "1000", "--y", "1000"], ["--remove", "Schema Probe"]],
        )
    assert check_lines("mapedit", out) == 2
    assert all(json.loads(line)["holds"] for line in out.splitlines())


def test_config_care_lines(tmp_path: Path) -> None:
    export = tmp_path / "office.toml"
    with SimThread(SimConfig(port=0, map_path=OFFICE)) as sim:
        out = run_all(
            sim,
            "config",
            [
                ["--export", str(export)],
                ["--import", str(export)],
                ["--reset", "Teleop/Timeout"],
                ["--reload"],
            ],
        )
        bad = tmp_path / "bad.toml"
        bad.write_text('format = "rtmu-config-1"\n["Teleop"]\n"Timeout" = "99"\n"NoSuchParameter" = "1"\n')
        refused = rtmu(sim, "config", "--import", str(bad))  # does not fit: nothing is sent
    assert refused.returncode == EXIT_REFUSED, refused.stderr
    assert check_lines("config", out + refused.stdout) == 5
    assert json.loads(refused.stdout)["problems"]


def test_an_interrupted_navigation_ends_with_its_outcome_line(sims: dict[str, SimThread]) -> None:
    sim = sims["aram"]
    proc = subprocess.Popen(
        [*RTMU, "goto", f"127.0.0.1:{sim.port}", "Corridor End", "--json", "--timeout", cli_timeout(5)],
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
            [*RTMU, "fleet", f"127.0.0.1:{fleet.port}", "--json", "--timeout", cli_timeout(5)],
            capture_output=True,
            text=True,
            timeout=60,
        )
    assert done.returncode == 0, done.stderr
    assert check_lines("fleet", done.stdout) == 1

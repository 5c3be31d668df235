"""Every subcommand's failure paths exit with a code of the one table, and one its help lists.

Each case runs the real command (in this process, or as a process where a signal, a pipe or the
environment matter) against the simulator, a port where nothing listens, or a server that
accepts and never answers, and checks the code against ``rtmu.base.exit_codes.EXIT_CODES`` and
the subcommand's own ``EXITS`` (what its ``--help`` prints). Signals (Ctrl-C 130, SIGHUP 129,
SIGTERM 143) for every observer, record and bridge included: tests/client/test_observers.py.
"""

from __future__ import annotations

import importlib
import os
import socket
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from patience import cli_timeout
from rtmu.base import exit_codes
from rtmu.base.exit_codes import (
    EXIT_BAD_FILE,
    EXIT_CONNECTION,
    EXIT_FOREIGN_CONFIG,
    EXIT_NO_DISPLAY,
    EXIT_OK,
    EXIT_REFUSED,
    EXIT_SIGPIPE,
    EXIT_TIMEOUT,
    EXIT_UNSUPPORTED,
    EXIT_USAGE,
    EXIT_WHY_DEAD_ZONE,
    EXIT_WHY_ESTOP,
    EXIT_WHY_STALLED,
)
from rtmu.cli import main
from rtmu.package_data import project_map
from rtmu.sim import SimConfig, SimThread
from simulators import simulator

REPO = Path(__file__).resolve().parents[1]
ARENA = project_map("arena.map")
RTMU = [sys.executable, "-m", "rtmu"]

NETWORK_ARGS: dict[str, list[str]] = {
    "bridge": ["--foxglove", "--ws-port", "0"],
    "call": ["updateNumbers"],
    "commands": [],
    "config": [],
    "dock": [],
    "doctor": [],
    "drawings": [],
    "drive": ["--trans", "30", "--seconds", "1"],
    "files": ["ls"],
    "fleet": [],
    "goals": [],
    "goto": ["Lab"],
    "home": [],
    "image": ["--out", "{tmp}/x.jpg"],
    "localize": ["1", "2", "3"],
    "map": ["--out", "{tmp}/x.map"],
    "mapedit": ["--check-map"],
    "patrol": ["Loop"],
    "probe": [],
    "ptz": [],
    "record": ["--out", "{tmp}/x.mcap", "--seconds", "1"],
    "routes": [],
    "run": ["Anything"],
    "say": ["hello"],
    "scan": ["status"],
    "status": ["--once"],
    "video": ["--seconds", "1"],
    "watch": ["--seconds", "1"],
    "why": [],
}
"""Every subcommand that dials a robot server, with what it needs besides HOST[:PORT]."""


def declared(name: str) -> tuple[int, ...]:
    module = importlib.import_module(f"rtmu.subcommands.{name}")
    return tuple(getattr(module, "EXITS", exit_codes.NETWORK))


def check(name: str, code: int, expected: int) -> None:
    assert code in exit_codes.EXIT_CODES, f"rtmu {name} exited {code}, a code the table does not have"
    assert code in declared(name), f"rtmu {name} exited {code}, which its --help does not list"
    assert code == expected, f"rtmu {name} exited {code}, not {expected}"


def run(name: str, *argv: str) -> int:
    try:
        return main([name, *argv])
    except SystemExit as exc:  # argparse's own refusals
        return int(exc.code or 0)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


sim = simulator(scope="module", map_path=ARENA)


def test_every_network_subcommand_is_covered() -> None:
    from cli.test_cli_contract import SUBPARSERS

    offline = {"decode", "mapinfo", "replay", "sim"}
    assert set(SUBPARSERS.choices) == set(NETWORK_ARGS) | offline


@pytest.mark.parametrize("name", sorted(NETWORK_ARGS))
def test_nothing_listening_is_a_connection_failure(name: str, tmp_path: Path) -> None:
    argv = [a.format(tmp=tmp_path) for a in NETWORK_ARGS[name]]
    code = run(name, f"127.0.0.1:{free_port()}", *argv, "--timeout", "2")
    expected = exit_codes.EXIT_DOCTOR_TCP if name == "doctor" else EXIT_CONNECTION
    check(name, code, expected)


@pytest.mark.parametrize(
    "name", ["status", "probe", "goals", "record", "config", "files", "scan", "mapedit", "why", "call"]
)
def test_a_server_that_never_answers_is_a_timeout(name: str, tmp_path: Path) -> None:
    with socket.socket() as listener:
        listener.bind(("127.0.0.1", 0))
        listener.listen(4)  # accepts (the kernel does) and never says a word
        port = listener.getsockname()[1]
        argv = [a.format(tmp=tmp_path) for a in NETWORK_ARGS[name]]
        check(name, run(name, f"127.0.0.1:{port}", *argv, "--timeout", "1"), EXIT_TIMEOUT)


def test_server_side_failures_have_their_codes(sim: SimThread, tmp_path: Path) -> None:
    where = f"127.0.0.1:{sim.port}"
    check("routes", run("routes", where, "--timeout", cli_timeout(5)), EXIT_UNSUPPORTED)  # an LD robot's data
    check(
        "goto", run("goto", where, "Nowhere", "--timeout", cli_timeout(5)), EXIT_USAGE
    )  # not a goal of the map
    refused = run("config", where, "--set", "Teleop/Timeout=-1", "--timeout", cli_timeout(5))
    check("config", refused, EXIT_REFUSED)
    check(
        "ptz", run("ptz", where, "--pan", "200", "--timeout", cli_timeout(5)), EXIT_USAGE
    )  # the head's own limits
    check("status", run("status", where, "--interval", "5"), EXIT_USAGE)
    check("image", run("image", where, "--out", str(tmp_path / "x.jpg"), "--quality", "0"), EXIT_USAGE)


def test_the_commissioning_and_console_commands_failures(sim: SimThread, tmp_path: Path) -> None:
    """files, scan, mapedit, config's care and call: each failure has the code its help lists."""
    where = f"127.0.0.1:{sim.port}"
    missing = ["get", "no/such.txt", "--out", str(tmp_path / "x.bin")]
    check(
        "files", run("files", where, *missing, "--timeout", cli_timeout(5)), EXIT_REFUSED
    )  # the robot's words
    assert not (tmp_path / "x.bin").exists()
    check(
        "files", run("files", where, "ls", "../etc", "--timeout", cli_timeout(5)), EXIT_USAGE
    )  # before connecting
    check(
        "files", run("files", where, "rm", "x.txt", "--timeout", cli_timeout(5)), EXIT_USAGE
    )  # no --yes, no terminal
    check("scan", run("scan", where, "stop", "--timeout", cli_timeout(5)), EXIT_REFUSED)  # no scan is running
    check("scan", run("scan", where, "loop", "start", "--timeout", cli_timeout(5)), EXIT_REFUSED)
    check(
        "mapedit", run("mapedit", where, "--remove", "No Such Goal", "--timeout", cli_timeout(5)), EXIT_USAGE
    )
    check(
        "mapedit", run("mapedit", where, "--add-goal", "X", "--timeout", cli_timeout(5)), EXIT_USAGE
    )  # no --x --y
    check("config", run("config", where, "--reset", "No/Such", "--timeout", cli_timeout(5)), EXIT_USAGE)
    check("call", run("call", where, "noSuchData", "--timeout", cli_timeout(5)), EXIT_USAGE)
    check(
        "call", run("call", where, "gotoGoal", "Goal", "--timeout", cli_timeout(5)), EXIT_USAGE
    )  # needs --yes
    check("call", run("call", where, "updateNumbers", "--timeout", cli_timeout(5)), EXIT_OK)


def test_why_and_a_drive_that_did_not_move_exit_with_the_causes_code(tmp_path: Path) -> None:
    """Asked to move and not moved is never 0: the cause's code, each one its help lists."""
    with SimThread(SimConfig(port=0, map_path=ARENA)) as sim:
        where = f"127.0.0.1:{sim.port}"
        check("why", run("why", where, "--timeout", cli_timeout(5)), EXIT_OK)
        check(
            "drive",
            run("drive", where, "--trans", "5", "--seconds", "0.3", "--timeout", cli_timeout(5)),
            EXIT_WHY_DEAD_ZONE,
        )
        check("run", run("run", where, "SimulatorStallMotors", "--timeout", cli_timeout(5)), EXIT_OK)
        check(
            "drive",
            run("drive", where, "--trans", "50", "--seconds", "0.3", "--timeout", cli_timeout(5)),
            EXIT_WHY_STALLED,
        )
        check("run", run("run", where, "SimulatorClearStall", "--timeout", cli_timeout(5)), EXIT_OK)
        check("run", run("run", where, "SimulatorEStop", "--timeout", cli_timeout(5)), EXIT_OK)
        check("why", run("why", where, "--timeout", cli_timeout(5)), EXIT_WHY_ESTOP)
        check(
            "doctor", run("doctor", where, "--timeout", cli_timeout(5)), EXIT_WHY_ESTOP
        )  # its last step asks why


def test_an_ld_robots_configuration_and_camera(tmp_path: Path) -> None:
    """An Omron LD robot (aram): a configuration RTMU cannot edit yet is 18, no camera is 4."""
    with SimThread(SimConfig(port=0, map_path=ARENA, profile="aram")) as aram:
        where = f"127.0.0.1:{aram.port}"
        check("config", run("config", where, "--timeout", cli_timeout(5)), EXIT_FOREIGN_CONFIG)
        check("config", run("config", where, "--defaults", "--timeout", cli_timeout(5)), EXIT_FOREIGN_CONFIG)
        check("video", run("video", where, "--seconds", "1", "--timeout", cli_timeout(5)), EXIT_UNSUPPORTED)
        check(
            "scan", run("scan", where, "loop", "start", "--timeout", cli_timeout(5)), EXIT_UNSUPPORTED
        )  # not on 6MTX


def test_files_named_on_the_command_line(tmp_path: Path) -> None:
    missing = str(tmp_path / "missing.bin")
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"hello, this is not a recording" * 40)
    for name in ("decode", "mapinfo", "replay"):
        check(name, run(name, missing), EXIT_USAGE)
    check("decode", run("decode", str(junk)), EXIT_BAD_FILE)
    check("mapinfo", run("mapinfo", str(junk)), EXIT_BAD_FILE)
    check("replay", run("replay", str(junk)), EXIT_BAD_FILE)
    check("replay", run("replay", str(junk), "--conn", "0"), EXIT_USAGE)
    check("sim", run("sim", "--map", missing, "--port", "0"), EXIT_USAGE)


def test_a_password_comes_only_from_a_file_a_terminal_or_stdin_when_asked(sim: SimThread) -> None:
    """Piped, a line is no longer taken for the password, nor an empty stdin for an empty one."""
    where = f"127.0.0.1:{sim.port}"
    piped = subprocess.run(
        [*RTMU, "status", where, "--user", "alice", "--once"],
        input="secret\n",
        capture_output=True,
        text=True,
    )
    assert piped.returncode == EXIT_USAGE and "--password-stdin" in piped.stderr, piped.stderr
    empty = subprocess.run(
        [*RTMU, "status", where, "--user", "alice", "--once", "--password-stdin"],
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
    )
    assert empty.returncode == EXIT_USAGE and "without a password line" in empty.stderr, empty.stderr
    given = subprocess.run(
        [*RTMU, "status", where, "--user", "alice", "--once", "--password-stdin"],
        input="anything\n",
        capture_output=True,
        text=True,
    )
    assert given.returncode == 0, given.stderr  # the simulator has no user file: any password logs in


def test_the_window_without_a_display(tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    done = subprocess.run([*RTMU, "--no-connect"], env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == EXIT_NO_DISPLAY, done.stderr
    assert "cannot open a display" in done.stderr


def test_a_reader_that_goes_away_is_141(sim: SimThread) -> None:
    proc = subprocess.Popen(
        [*RTMU, "status", f"127.0.0.1:{sim.port}", "--interval", "10"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert proc.stdout is not None and proc.stderr is not None
    proc.stdout.readline()
    proc.stdout.close()  # `| head -1`
    err = threading.Thread(target=proc.stderr.read, daemon=True)
    err.start()
    assert proc.wait(60) == EXIT_SIGPIPE
    check("status", EXIT_SIGPIPE, EXIT_SIGPIPE)


def test_an_unreadable_recording_says_why_in_plain_words(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """No empty reason for a cut-short file, no byte tuple for one that is no MCAP at all."""
    junk = tmp_path / "notes.mcap"
    junk.write_bytes(b"hello, these are notes")
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(b"\x89MCAP0\r\n" + b"\x01" + b"\x00" * 20)  # MCAP's magic, then half a record
    check("replay", run("replay", str(junk)), EXIT_BAD_FILE)  # (decode reads it as the text it is)
    err = capsys.readouterr().err
    assert "it does not start as an MCAP file does" in err and "(104," not in err, err
    for name in ("replay", "decode"):
        check(name, run(name, str(cut)), EXIT_BAD_FILE)
        err = capsys.readouterr().err
        reason = err.rstrip().removesuffix(")")  # decode says its own sentence, the reader's in brackets
        assert reason.endswith("it is cut short: it ends in the middle of a record"), err

"""``rtmu files`` and ``rtmu scan`` against the simulator: output, ``--json``, exit codes, early checks."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_OK, EXIT_REFUSED, EXIT_USAGE
from rtmu.cli import main
from rtmu.sim import SimThread
from simulators import running

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture
def robot(tmp_path: Path) -> Path:
    root = tmp_path / "robot"
    (root / "maps").mkdir(parents=True)
    (root / "maps" / "office.map").write_bytes(b"2D-Map\n" * 100)
    (root / "notes.txt").write_text("hello\n")
    return root


@pytest.fixture
def sim(robot: Path) -> Iterator[SimThread]:
    with running(files_dir=robot, files_default_dir="maps") as s:
        yield s


def addr(sim: SimThread) -> str:
    return f"127.0.0.1:{sim.port}"


def closed_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_ls_text_and_json(sim: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["files", addr(sim), "ls"]) == EXIT_OK
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[0] == "-" and lines[0].endswith("maps/") and lines[1].endswith("notes.txt")
    assert main(["files", addr(sim), "ls", "maps", "--json", "--timeout", cli_timeout(5)]) == EXIT_OK
    doc = json.loads(capsys.readouterr().out)
    assert doc["folder"] == "maps" and [(e["name"], e["type"], e["size"]) for e in doc["entries"]] == [
        ("office.map", "file", 700)
    ]


def test_get_put_rm_round_trip(
    sim: SimThread, robot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "got.map"
    assert main(["files", addr(sim), "get", "maps/office.map", "--out", str(out), "--json"]) == EXIT_OK
    doc = json.loads(capsys.readouterr().out)
    assert (
        doc["bytes"] == 700 == doc["listed_size"]
        and out.read_bytes() == (robot / "maps" / "office.map").read_bytes()
    )
    local = tmp_path / "new.map"
    local.write_bytes(b"new map")
    assert main(["files", addr(sim), "put", str(local), "--json"]) == EXIT_OK  # into the default folder
    assert json.loads(capsys.readouterr().out)["remote"] == "maps/new.map"
    assert (robot / "maps" / "new.map").read_bytes() == b"new map"
    assert main(["files", addr(sim), "put", str(local), "extra/"]) == EXIT_REFUSED  # no such folder
    assert "no such folder" in capsys.readouterr().err
    assert main(["files", addr(sim), "rm", "maps/new.map", "--yes", "--json"]) == EXIT_OK
    assert json.loads(capsys.readouterr().out) == {"deleted": "maps/new.map"}
    assert not (robot / "maps" / "new.map").exists()


def test_an_existing_output_is_refused_before_connecting(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "office.map").write_text("mine")
    nobody = f"127.0.0.1:{closed_port()}"
    assert main(["files", nobody, "get", "maps/office.map", "--out", str(tmp_path)]) == EXIT_USAGE
    assert "already exists (give --force" in capsys.readouterr().err
    assert main(["files", nobody, "get", "../x"]) == EXIT_USAGE
    assert main(["files", nobody, "get", "x", "--out", str(tmp_path / "no" / "such")]) == EXIT_USAGE
    assert main(["files", nobody, "put", str(tmp_path / "missing.map")]) == EXIT_USAGE
    assert main(["scan", nobody, "stop", "--download", str(tmp_path / "nowhere")]) == EXIT_USAGE
    assert main(["scan", nobody, "start", "../x"]) == EXIT_USAGE
    assert (tmp_path / "office.map").read_text() == "mine"


def test_force_replaces_and_put_refuses_a_file_the_robot_has(
    sim: SimThread, robot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "office.map").write_text("old")
    assert main(["files", addr(sim), "get", "maps/office.map", "--out", str(tmp_path), "--force"]) == EXIT_OK
    assert (tmp_path / "office.map").read_bytes() == (robot / "maps" / "office.map").read_bytes()
    (tmp_path / "notes.txt").write_text("replacement")
    assert main(["files", addr(sim), "put", str(tmp_path / "notes.txt"), "notes.txt"]) == EXIT_USAGE
    assert "already has a file 'notes.txt'" in capsys.readouterr().err
    assert (robot / "notes.txt").read_text() == "hello\n"
    assert main(["files", addr(sim), "put", str(tmp_path / "notes.txt"), "notes.txt", "--force"]) == EXIT_OK
    assert (robot / "notes.txt").read_text() == "replacement"


def test_rm_without_a_terminal_needs_yes(
    sim: SimThread, robot: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["files", addr(sim), "rm", "notes.txt"]) == EXIT_USAGE
    assert "give --yes" in capsys.readouterr().err and (robot / "notes.txt").exists()
    assert main(["files", addr(sim), "rm", "nope.txt", "--yes"]) == EXIT_REFUSED


@pytest.mark.parametrize(("answer", "deleted"), [(b"y\n", True), (b"n\n", False)])
def test_rm_asks_on_a_terminal_naming_the_file(
    sim: SimThread, robot: Path, answer: bytes, deleted: bool
) -> None:
    master, slave = os.openpty()
    env = {**os.environ, "PYTHONPATH": str(REPO / "src")}
    try:
        proc = subprocess.Popen(
            [sys.executable, "-m", "rtmu", "files", addr(sim), "rm", "notes.txt"],
            stdin=slave, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
        )  # fmt: skip
        os.write(master, answer)
        out, err = proc.communicate(timeout=60)
    finally:
        os.close(master)
        os.close(slave)
    assert f"Delete 'notes.txt' on {addr(sim)}? [y/N]".encode() in out
    assert proc.returncode == (EXIT_OK if deleted else EXIT_USAGE), err
    assert (robot / "notes.txt").exists() != deleted


def test_scan_start_status_loop_stop_download(
    sim: SimThread, robot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["scan", addr(sim), "status", "--json"]) == EXIT_OK
    assert json.loads(capsys.readouterr().out) == {"scanning": False, "name": "", "file": ""}
    assert main(["scan", addr(sim), "loop", "start"]) == EXIT_REFUSED
    assert "no scan is running" in capsys.readouterr().err
    assert main(["scan", addr(sim), "start", "Hall", "--json"]) == EXIT_OK
    assert json.loads(capsys.readouterr().out) == {"scanning": True, "file": "hall.2d"}
    assert main(["scan", addr(sim), "start", "Hall"]) == EXIT_REFUSED
    assert "already running" in capsys.readouterr().err
    assert main(["scan", addr(sim), "status"]) == EXIT_OK
    assert capsys.readouterr().out == "scanning hall (file hall.2d)\n"
    assert main(["scan", addr(sim), "loop", "start", "7", "--json"]) == EXIT_OK
    assert json.loads(capsys.readouterr().out) == {"loop": "start", "tag": "7", "taken": True}
    assert main(["scan", addr(sim), "loop", "end", "7"]) == EXIT_OK
    assert capsys.readouterr().out == "loop end tagged '7'\n"
    down = tmp_path / "scans"
    down.mkdir()
    assert (
        main(["scan", addr(sim), "stop", "--download", str(down), "--json", "--timeout", cli_timeout(5)])
        == EXIT_OK
    )
    doc = json.loads(capsys.readouterr().out)
    assert doc["file"] == "hall.2d" and doc["downloaded"] == str(down / "hall.2d")
    assert (down / "hall.2d").read_bytes() == (robot / "hall.2d").read_bytes()
    assert main(["scan", addr(sim), "stop"]) == EXIT_REFUSED
    assert "no scan is running" in capsys.readouterr().err

"""The command line's human text in the operator's language, its ``--json`` in stable English.

Against the simulator: ``rtmu doctor`` and ``rtmu status`` read in German (words, decimal commas), and
the same runs with ``--json`` give the English sentences and plain numbers a script parses.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterator
from pathlib import Path

import pytest

from rtmu.base import i18n
from rtmu.cli import main
from rtmu.package_data import project_map
from rtmu.sim import SimConfig, SimThread
from rtmu.subcommands._navigate import EXIT_NAV_LOST


@pytest.fixture(scope="module")
def sim() -> Iterator[SimThread]:
    with SimThread(SimConfig(port=0, map_path=project_map("office.map"))) as running:
        yield running


@pytest.fixture
def german(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path))  # doctor keeps its last report there
    i18n.use(["de"])
    try:
        yield
    finally:
        i18n.use(["en"])


def test_doctor_reads_german_and_its_json_stays_english(
    sim: SimThread, german: None, capsys: pytest.CaptureFixture[str]
) -> None:
    where = f"127.0.0.1:{sim.port}"
    main(["doctor", where, "--timeout", "5", "--link-seconds", "0"])
    out = capsys.readouterr().out
    assert f"TCP-Verbindung: verbunden mit {where} in " in out, out
    assert "Vorstellung des Servers: ein ArNetworking-Server" in out, out
    assert re.search(r"erster Status: Roboter bei \(-?[\d.]+; -?[\d.]+\) mm, -?\d+°, Akku \d+,\d V", out), out
    assert "connected to" not in out and "robot at" not in out, out
    main(["doctor", where, "--timeout", "5", "--link-seconds", "0", "--json"])
    report = json.loads(capsys.readouterr().out)
    steps = {s["step"]: s for s in report["steps"]}
    assert steps["tcp"]["title"] == "TCP connection"
    assert steps["tcp"]["summary"].startswith(f"connected to {where} in ")
    assert re.fullmatch(
        r"robot at \(-?\d+, -?\d+\) mm, -?\d+°, battery \d+\.\d V.*", steps["status"]["summary"]
    )


def test_status_line_reads_german_and_json_keeps_plain_numbers(
    sim: SimThread, german: None, capsys: pytest.CaptureFixture[str]
) -> None:
    where = f"127.0.0.1:{sim.port}"
    assert main(["status", where, "--once", "--timeout", "5"]) == 0
    line = capsys.readouterr().out
    assert re.search(r"Akku=\d+,\d V", line), line
    assert main(["status", where, "--once", "--timeout", "5", "--json"]) == 0
    obj = json.loads(capsys.readouterr().out.splitlines()[-1])
    assert isinstance(obj["battery_v"], float | int) and isinstance(obj["x"], int)


def test_why_reads_german_with_its_numbers_and_its_json_stays_english(
    german: None, capsys: pytest.CaptureFixture[str]
) -> None:
    """A drive inside ARIA's dead zone: its sentence carries percentages, said as German writes them."""
    with SimThread(SimConfig(port=0, map_path=project_map("office.map"))) as sim:
        where = f"127.0.0.1:{sim.port}"
        main(["drive", where, "--trans", "2.5", "--seconds", "0.3", "--timeout", "5"])
        err = capsys.readouterr().err
        assert "Totzone" in err and "2,5 %" in err, err
        main(["run", where, "SimulatorEStop", "--timeout", "5"])
        capsys.readouterr()
        main(["why", where, "--timeout", "5"])
        out = capsys.readouterr().out
        assert "der Not-Halt des Roboters ist gedrückt (der Server sagt" in out, out
        assert "  was zu tun ist: " in out, out
        main(["why", where, "--timeout", "5", "--json"])
        answer = json.loads(capsys.readouterr().out)
        assert answer["reasons"][0]["problem"].startswith("the robot's e-stop is pressed (the server says")


def test_a_refused_connection_is_said_in_german(german: None, capsys: pytest.CaptureFixture[str]) -> None:
    import socket

    with socket.socket() as s:  # a port nothing listens on: bound, never listening
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
        assert main(["status", f"127.0.0.1:{port}", "--once", "--timeout", "5"]) != 0
    err = capsys.readouterr().err
    assert f"Verbindung von 127.0.0.1:{port} abgelehnt (läuft der Roboterserver an diesem Port?)" in err, err


def test_a_wrong_password_is_said_in_german(
    german: None, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from simulators import users_file

    users = users_file(tmp_path, "teleop secret all")
    wrong = tmp_path / "password"
    wrong.write_text("not-it\n")
    with SimThread(SimConfig(port=0, map_path=None, users_path=users)) as sim:
        where = f"127.0.0.1:{sim.port}"
        argv = [
            "status",
            where,
            "--user",
            "teleop",
            "--password-file",
            str(wrong),
            "--once",
            "--timeout",
            "5",
        ]
        assert main(argv) != 0
    err = capsys.readouterr().err
    assert "Anmeldung abgelehnt: falscher Benutzername oder falsches Passwort" in err, err


def test_a_navigation_outcome_reads_german_and_its_json_stays_english(
    german: None, capsys: pytest.CaptureFixture[str]
) -> None:
    """A lost robot's goto: the server's own words as sent, RTMU's reason and the localize lines in German."""
    from client.navsim import fast_sim

    with fast_sim() as sim:
        assert sim.server is not None
        sim.call(sim.server.lose_localization)
        where = f"127.0.0.1:{sim.port}"
        argv = ["goto", where, "Room 101", "--timeout", "5", "--limit", "60"]
        assert main(argv) == EXIT_NAV_LOST
        err = capsys.readouterr().err
        said = "rtmu goto: Failed to get to Room 101 (Grund: der Roboter hat seine Position verloren)"
        assert said in err, err
        assert main([*argv, "--json"]) == EXIT_NAV_LOST
        last = json.loads(capsys.readouterr().out.splitlines()[-1])
        assert last["outcome"] == "failed" and last["reason"] == "the robot is lost", last
        assert main(["localize", where, "2500", "6000", "0", "--timeout", "5", "--limit", "60"]) == 0
        out = capsys.readouterr().out.splitlines()
        assert re.fullmatch(r"lokalisiert \(Wert 0,\d\d\)", out[-1]), out

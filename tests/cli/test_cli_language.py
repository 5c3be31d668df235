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

from patience import cli_timeout
from rtmu.base import i18n
from rtmu.base.exit_codes import EXIT_USAGE
from rtmu.cli import main
from rtmu.package_data import project_map
from rtmu.sim import SimConfig, SimThread
from rtmu.subcommands._nav_args import EXIT_NAV_LOST


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
    main(["doctor", where, "--timeout", cli_timeout(5), "--link-seconds", "0"])
    out = capsys.readouterr().out
    assert f"TCP-Verbindung: verbunden mit {where} in " in out, out
    assert "Vorstellung des Servers: ein ArNetworking-Server" in out, out
    assert re.search(r"erster Status: Roboter bei \(-?[\d.]+; -?[\d.]+\) mm, -?\d+°, Akku \d+,\d V", out), out
    assert "connected to" not in out and "robot at" not in out, out
    main(["doctor", where, "--timeout", cli_timeout(5), "--link-seconds", "0", "--json"])
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
    assert main(["status", where, "--once", "--timeout", cli_timeout(5)]) == 0
    line = capsys.readouterr().out
    assert re.search(r"Akku=\d+,\d V", line), line
    assert main(["status", where, "--once", "--timeout", cli_timeout(5), "--json"]) == 0
    obj = json.loads(capsys.readouterr().out.splitlines()[-1])
    assert isinstance(obj["battery_v"], float | int) and isinstance(obj["x"], int)


def test_why_reads_german_with_its_numbers_and_its_json_stays_english(
    german: None, capsys: pytest.CaptureFixture[str]
) -> None:
    """A drive inside ARIA's dead zone: its sentence carries percentages, said as German writes them."""
    with SimThread(SimConfig(port=0, map_path=project_map("office.map"))) as sim:
        where = f"127.0.0.1:{sim.port}"
        main(["drive", where, "--trans", "2.5", "--seconds", "0.3", "--timeout", cli_timeout(5)])
        err = capsys.readouterr().err
        assert "Totzone" in err and "2,5 %" in err, err
        main(["run", where, "SimulatorEStop", "--timeout", cli_timeout(5)])
        capsys.readouterr()
        main(["why", where, "--timeout", cli_timeout(5)])
        out = capsys.readouterr().out
        assert "der Not-Halt des Roboters ist gedrückt (der Server sagt" in out, out
        assert "  was zu tun ist: " in out, out
        main(["why", where, "--timeout", cli_timeout(5), "--json"])
        answer = json.loads(capsys.readouterr().out)
        assert answer["reasons"][0]["problem"].startswith("the robot's e-stop is pressed (the server says")


def test_a_refused_connection_is_said_in_german(german: None, capsys: pytest.CaptureFixture[str]) -> None:
    import socket

    with socket.socket() as s:  # a port nothing listens on: bound, never listening
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
        assert main(["status", f"127.0.0.1:{port}", "--once", "--timeout", cli_timeout(5)]) != 0
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
        argv = ["goto", where, "Room 101", "--timeout", cli_timeout(5), "--limit", "60"]
        assert main(argv) == EXIT_NAV_LOST
        err = capsys.readouterr().err
        said = "rtmu goto: Failed to get to Room 101 (Grund: der Roboter hat seine Position verloren)"
        assert said in err, err
        assert main([*argv, "--json"]) == EXIT_NAV_LOST
        last = json.loads(capsys.readouterr().out.splitlines()[-1])
        assert last["outcome"] == "failed" and last["reason"] == "the robot is lost", last
        assert (
            main(["localize", where, "2500", "6000", "0", "--timeout", cli_timeout(5), "--limit", "60"]) == 0
        )
        out = capsys.readouterr().out.splitlines()
        assert re.fullmatch(r"lokalisiert \(Wert 0,\d\d\)", out[-1]), out


def test_decode_reads_german_and_its_json_stays_english(
    german: None, capsys: pytest.CaptureFixture[str]
) -> None:
    """A capture's header, folded runs, notes and summary in German; the packets' own names and fields
    (the capture's words) as they are; --json's notes in English."""
    from testdata import CAPTURES

    assert main(["decode", str(CAPTURES / "map-binary-columbia.pcap")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("# map-binary-columbia.pcap: pcap, Link-Typ "), out[:200]
    assert "Felder (Prüfsumme in Ordnung, wo nicht markiert)" in out
    assert re.search(r"… 63818 weitere getMap-Pakete über [\d.]+,\d{3} s \(--all zeigt sie\) …", out), out
    assert "(Ende der Antwort)" in out and "line='2D-Map'" in out
    assert "== Zusammenfassung" in out and "  verworfen: nichts" in out
    assert re.search(r"Mitschnitt: [\d.]+ Frames, [\d.]+,\d{3} s", out), out
    assert "more getMap" not in out and "summary" not in out
    assert main(["decode", "--json", str(CAPTURES / "map-binary-columbia.pcap")]) == 0
    notes = {json.loads(line).get("note") for line in capsys.readouterr().out.splitlines()}
    assert "end of reply" in notes and "Ende der Antwort" not in notes
    assert main(["decode", str(CAPTURES / "no-such.pcap")]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.startswith("rtmu decode: die Datei ist nicht lesbar (cannot read "), err  # reader: English


def test_a_packet_that_does_not_decode_is_said_in_german(
    german: None, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A login packet cut short: decode says so in German, the codec's own detail after it as it is."""
    from rtmu.protocol.packet import encode_packet

    raw = tmp_path / "short-login.bin"
    raw.write_bytes(encode_packet(2, b"\x07\x00\x00"))  # INTRODUCTION without its password digest
    assert main(["decode", str(raw)]) == 0
    out = capsys.readouterr().out
    assert "INTRODUCTION" in out and "!! nicht dekodierbar: FieldUnderrun: " in out, out
    assert "does not decode" not in out


def test_watch_reads_german_with_the_servers_words_as_sent(
    sim: SimThread, german: None, capsys: pytest.CaptureFixture[str]
) -> None:
    world = sim.server.world  # type: ignore[union-attr]
    sim.call(lambda: world.create_popup("Door open", "Close the door", kind=2, buttons=("OK", "", "")))
    where = f"127.0.0.1:{sim.port}"
    assert main(["watch", where, "--seconds", "0.5", "--timeout", cli_timeout(5)]) == 0
    out = capsys.readouterr().out
    assert re.search(r"Meldung geöffnet #\d+ \(Warnung\) Door open: Close the door \[OK\]", out), out
    assert re.search(r"^ +\d+,\d{3}  Modus ", out, re.M), out  # the time with German's decimal comma
    assert "popup opened" not in out and "mode " not in out, out
    assert main(["watch", where, "--seconds", "0.5", "--timeout", cli_timeout(5), "--json"]) == 0
    events = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert {"popup_opened", "mode"} <= {e["event"] for e in events}


def test_sim_says_where_it_listens_in_german_at_a_terminal_and_in_english_to_a_program() -> None:
    """At a terminal (a pty) a person reads the start line in their language; through a pipe a program
    reads the English it parses (the port of --port 0), whatever the language."""
    import os
    import pty
    import select
    import signal
    import socket
    import subprocess
    import sys

    env = {**os.environ, "LANGUAGE": "de", "PYTHONUNBUFFERED": "1"}
    argv = [sys.executable, "-m", "rtmu", "sim", "--port", "0", "--no-camera", "--no-map"]
    main_end, tty_end = pty.openpty()
    proc = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=tty_end, stderr=tty_end, env=env)
    os.close(tty_end)
    said = b""

    def read_until(wanted: bytes) -> None:
        nonlocal said
        while wanted not in said:
            ready, _, _ = select.select([main_end], [], [], 60)
            assert ready, said  # nothing for a minute
            try:
                chunk = os.read(main_end, 4096)
            except OSError:  # EIO: every writer is gone
                chunk = b""
            assert chunk, said
            said += chunk

    try:
        read_until(b"\n")
        port = int(re.search(rb"127\.0\.0\.1:(\d+)", said).group(1))  # type: ignore[union-attr]
        with socket.create_connection(("127.0.0.1", port), timeout=30) as client:
            assert client.recv(64)  # its introduction: it serves, its signal handlers are in place
        proc.send_signal(signal.SIGINT)
        read_until(b"SHUTDOWN")
        proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(timeout=30)
        os.close(main_end)
    text = said.decode()
    assert re.search(
        r"rtmu sim: ARIA-Roboterserver lauscht auf 127\.0\.0\.1:\d+ und bietet keine Karte; ", text
    ), text
    assert "; keine Kamera; Dateien in " in text, text
    assert "rtmu sim: wird beendet (Clients erhalten SHUTDOWN)" in text, text
    piped = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, text=True, env=env)
    try:
        assert piped.stdout is not None
        line = piped.stdout.readline()
        assert re.search(r"ARIA robot server listening on 127\.0\.0\.1:\d+, serving no map; ", line), line
    finally:
        piped.send_signal(signal.SIGINT)
        piped.wait(timeout=60)


def test_the_guardians_refusal_reaches_the_operator_in_german(
    german: None, capsys: pytest.CaptureFixture[str]
) -> None:
    """The guardian is a process of its own: it speaks the language chosen here (``child_environment``),
    its refusal and the server's own words inside RTMU's German warning."""
    with SimThread(SimConfig(port=0, seed=1, max_clients=1)) as sim:  # the drive's own login takes the slot
        argv = [
            "drive",
            f"127.0.0.1:{sim.port}",
            "--trans",
            "50",
            "--seconds",
            "0.3",
            "--timeout",
            cli_timeout(5),
        ]
        assert main(argv) == 0
    err = capsys.readouterr().err
    assert (
        "rtmu drive: Warnung: Wächter nicht verfügbar (Anmeldung abgelehnt: am Server sind zu viele " in err
    )
    assert "angemeldet: Server rejecting connection since it would exceed the maximum number" in err, err


def test_a_missing_password_file_is_said_in_german(
    sim: SimThread, german: None, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    where = f"127.0.0.1:{sim.port}"
    argv = ["status", where, "--user", "teleop", "--password-file", str(tmp_path / "nope"), "--once"]
    assert main(argv) != 0
    err = capsys.readouterr().err
    assert "die mit --password-file angegebene Passwortdatei ist nicht lesbar: keine solche Datei" in err, err


def test_an_unknown_goal_and_a_wrong_usage_are_said_in_german(
    sim: SimThread, german: None, capsys: pytest.CaptureFixture[str]
) -> None:
    where = f"127.0.0.1:{sim.port}"
    assert main(["goto", where, "Nowhere", "--timeout", cli_timeout(5)]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert "rtmu goto: kein Ziel 'Nowhere' auf diesem Server (Ziele: " in err and "Room 101" in err, err
    assert main(["goto", where, "Lab B", "--x", "1", "--y", "2", "--timeout", cli_timeout(5)]) == EXIT_USAGE
    assert "entweder ZIEL oder --x/--y angeben, nicht beides" in capsys.readouterr().err


def test_mapinfo_reads_german_and_its_json_stays_english(
    german: None, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The summary's labels, the stale header's note and the plural in German with German numbers; the
    map's own words (category, object types, goal names) as written; --json's keys and numbers plain."""
    from testdata import ARIA_MAPS

    assert main(["mapinfo", str(ARIA_MAPS / "columbia.map")]) == 0
    out = capsys.readouterr().out
    assert "Kategorie:" in out and "2D-Map" in out and "category" not in out
    assert "63.311 (Kopf: 63.311)" in out  # German groups thousands with a point
    assert "(-4.780, -27.000) .. (19.560, 24.680)" in out and "20 mm" in out
    assert "ForbiddenLine 12" in out and '"Hallway 1"' in out
    stale = tmp_path / "stale.map"
    stale.write_text("2D-Map\nNumLines: 9\nLINES\n" + "0 0 1 1\n" * 10 + "DATA\nnot a point\nnor this\n")
    assert main(["mapinfo", str(stale)]) == 0
    out = capsys.readouterr().out
    assert "10 (Kopf: 9)  <- Kopf ist veraltet" in out and "(2 Datenzeilen übersprungen)" in out
    assert main(["mapinfo", str(ARIA_MAPS / "columbia.map"), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["points"] == 63311 and summary["category"] == "2D-Map"

"""``rtmu probe/status/map/drive/image`` against the simulator and scripted servers: output and exit codes."""

from __future__ import annotations

import io
import json
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from client.servers import SPECS, ServerThread, TestServer
from client.test_connection import free_port
from client.uiqueue import eventually
from patience import cli_timeout
from rtmu import mapfile as maps
from rtmu.base.exit_codes import (
    EXIT_CONNECTION,
    EXIT_OK,
    EXIT_TIMEOUT,
    EXIT_UNSUPPORTED,
    EXIT_USAGE,
    EXIT_WHY_DEAD_ZONE,
    EXIT_WHY_NO_DRIVE,
)
from rtmu.cli import main
from rtmu.package_data import project_map
from rtmu.sim import SimThread
from rtmu.subcommands._common import host_port
from simulators import simulator

ARENA = project_map("arena.map")
STATUS_KEYS = {"x", "y", "th", "vel", "rot_vel", "battery_v", "status", "mode"}


sim = simulator(scope="module", map_path=ARENA, users=("alice secret1 all", "bob pw2 RobotInfo"))


@pytest.fixture
def pwfile(tmp_path: Path) -> Path:
    p = tmp_path / "pw"
    p.write_text("secret1\n")
    return p


def addr(sim: SimThread) -> str:
    return f"127.0.0.1:{sim.port}"


def login(sim: SimThread, pwfile: Path) -> list[str]:
    return [addr(sim), "--user", "alice", "--password-file", str(pwfile), "--timeout", cli_timeout(5)]


def test_host_port_forms() -> None:
    assert host_port("robot") == ("robot", 7272)
    assert host_port("10.0.0.5:8000") == ("10.0.0.5", 8000)
    assert host_port("[::1]:7000") == ("::1", 7000)
    assert host_port("::1") == ("::1", 7272)
    with pytest.raises(Exception):  # noqa: B017
        host_port("robot:99999")


def test_probe_json_is_one_object(sim: SimThread, pwfile: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["probe", *login(sim, pwfile), "--json"]) == EXIT_OK
    out = capsys.readouterr().out
    obj = json.loads(out)
    assert out.count("\n") == 1 and obj["count"] == len(obj["data"]) > 50
    ratio = next(d for d in obj["data"] if d["name"] == "ratioDrive")
    assert (
        ratio["group"] == "Movement"
        and ratio["flags"] == ["RETURN_NONE"]
        and "transRatio" in ratio["arguments"]
    )


def test_probe_text_groups(sim: SimThread, pwfile: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["probe", *login(sim, pwfile)]) == EXIT_OK
    out = capsys.readouterr().out
    assert "Movement:" in out and "ratioDrive" in out and "offers" in out.splitlines()[0]


def test_status_once_and_streamed_json(
    sim: SimThread, pwfile: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["status", *login(sim, pwfile), "--once", "--json"]) == EXIT_OK
    obj = json.loads(capsys.readouterr().out)
    assert set(obj) == STATUS_KEYS and obj["battery_v"] > 10
    assert main(["status", *login(sim, pwfile), "--json", "--count", "3", "--interval", "50"]) == EXIT_OK
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 3 and all(set(json.loads(line)) == STATUS_KEYS for line in lines)
    assert main(["status", *login(sim, pwfile), "--once"]) == EXIT_OK
    assert "battery=" in capsys.readouterr().out


def test_password_from_a_pipe(sim: SimThread, monkeypatch: pytest.MonkeyPatch, capsys) -> None:  # type: ignore[no-untyped-def]
    monkeypatch.setattr("sys.stdin", io.StringIO("secret1\n"))
    assert main(["status", addr(sim), "--user", "alice", "--once"]) == EXIT_USAGE  # only when asked to
    assert "--password-stdin" in capsys.readouterr().err
    monkeypatch.setattr("sys.stdin", io.StringIO("secret1\n"))
    assert main(["status", addr(sim), "--user", "alice", "--password-stdin", "--once"]) == EXIT_OK
    monkeypatch.setattr("sys.stdin", io.StringIO("wrong\n"))
    assert main(["status", addr(sim), "--user", "alice", "--password-stdin", "--once"]) == EXIT_CONNECTION
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("rtmu status: login refused: wrong user name or password")


def test_map_binary_and_text(sim: SimThread, pwfile: Path, tmp_path: Path) -> None:
    expected = maps.read_map(ARENA)
    for extra, name in (([], "bin.map"), (["--text"], "text.map")):
        out = tmp_path / name
        assert main(["map", *login(sim, pwfile), "--out", str(out), *extra]) == EXIT_OK
        got = maps.read_map(out)
        assert got.num_points == expected.num_points and got.num_lines == expected.num_lines


def test_image(sim: SimThread, pwfile: Path, tmp_path: Path) -> None:
    out = tmp_path / "cam.jpg"
    assert main(["image", *login(sim, pwfile), "--out", str(out)]) == EXIT_OK
    data = out.read_bytes()
    assert data[:2] == b"\xff\xd8" and data.rstrip(b"\x00")[-2:] == b"\xff\xd9"
    again = ["image", *login(sim, pwfile), "--out", str(out), "--camera", "Nope"]
    assert main(again) == EXIT_USAGE, "an existing picture is not replaced without --force"
    assert main([*again, "--force"]) == EXIT_UNSUPPORTED
    assert out.read_bytes() == data, "a failed picture leaves the old one as it was"


def test_drive_moves_then_stops(sim: SimThread, pwfile: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["drive", *login(sim, pwfile), "--trans", "60", "--seconds", "0.5", "--json"])
    assert code == EXIT_OK
    obj = json.loads(capsys.readouterr().out)
    assert set(obj["before"]) == STATUS_KEYS and obj["seconds"] == 0.5
    moved = abs(obj["after"]["x"] - obj["before"]["x"]) + abs(obj["after"]["y"] - obj["before"]["y"])
    assert moved > 20
    snap = sim.snapshot()
    assert snap.trans_ratio == 0 and snap.mode_name == "stop" and snap.vel == 0


def test_user_without_movement_rights_cannot_drive(sim: SimThread, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    pw = tmp_path / "bob"
    pw.write_text("pw2")
    args = [
        "drive",
        addr(sim),
        "--user",
        "bob",
        "--password-file",
        str(pw),
        "--trans",
        "10",
        "--seconds",
        "1",
    ]
    assert main(args) == EXIT_WHY_NO_DRIVE  # said as rtmu why says it (rtmu.client.why)
    assert "ratioDrive" in capsys.readouterr().err


def test_usage_errors_exit_2(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    assert main(["drive", "127.0.0.1", "--trans", "500", "--seconds", "1"]) == EXIT_USAGE
    assert main(["drive", "127.0.0.1", "--seconds", "0"]) == EXIT_USAGE
    with pytest.raises(SystemExit) as info:
        main(["status", "127.0.0.1:70000"])
    assert info.value.code == EXIT_USAGE
    missing = tmp_path / "nope"
    assert main(["status", "127.0.0.1", "--password-file", str(missing), "--once"]) == EXIT_USAGE
    assert "cannot read the password file" in capsys.readouterr().err


@pytest.mark.parametrize(
    "given",
    [
        ["--password", "secret1"],
        ["--password=secret1"],
        ["--pass", "secret1"],
        ["--password-file", "secret1"],
    ],
)
def test_a_password_on_the_command_line_is_refused_and_never_repeated(
    given: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    try:
        code = main(["status", f"127.0.0.1:{free_port()}", "--user", "alice", *given, "--once"])
    except SystemExit as exc:
        code = exc.code  # type: ignore[assignment]
    err = capsys.readouterr().err
    assert code == EXIT_USAGE
    assert "secret1" not in err


def test_password_file_is_not_abbreviated(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    pw = tmp_path / "pw"
    pw.write_text("secret1")
    with pytest.raises(SystemExit) as info:
        main(["status", "127.0.0.1", "--password-f", str(pw), "--once"])
    assert info.value.code == EXIT_USAGE
    assert "--password-f" in capsys.readouterr().err


def test_refused_exits_3(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["probe", f"127.0.0.1:{free_port()}", "--timeout", "2"]) == EXIT_CONNECTION
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "refused" in err


def test_silent_server_times_out_with_5(capsys: pytest.CaptureFixture[str]) -> None:
    with ServerThread(TestServer(silent=True)) as server:
        assert main(["status", f"127.0.0.1:{server.port}", "--once", "--timeout", "0.3"]) == EXIT_TIMEOUT
    assert "did not complete the login" in capsys.readouterr().err


def test_a_web_server_is_named_with_3_not_timed_out(capsys: pytest.CaptureFixture[str]) -> None:
    import socket
    import threading

    listener = socket.create_server(("127.0.0.1", 0))
    port = listener.getsockname()[1]
    held: list[socket.socket] = []

    def serve() -> None:  # a chatty non-ArNetworking peer that never closes
        conn, _ = listener.accept()
        held.append(conn)
        conn.sendall(b"<html><body>nothing to see</body></html>\n" * 200)

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        assert main(["probe", f"127.0.0.1:{port}", "--timeout", cli_timeout(30)]) == EXIT_CONNECTION
    finally:
        thread.join(5)
        for conn in held:
            conn.close()
        listener.close()
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not an ArNetworking server" in err


def test_unsupported_exits_4(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    bare = [row for row in SPECS if row[0] in ("updateNumbers", "stop")]
    with ServerThread(TestServer(bare)) as server:
        target = f"127.0.0.1:{server.port}"
        assert main(["image", target, "--out", str(tmp_path / "x.jpg")]) == EXIT_UNSUPPORTED
        assert main(["map", target, "--out", str(tmp_path / "x.map")]) == EXIT_UNSUPPORTED
        lines = capsys.readouterr().err.splitlines()
        assert len(lines) == 2 and all(line.startswith("rtmu ") for line in lines)
        # A server that offers no driving is told as rtmu why tells it, with its own exit code.
        assert main(["drive", target, "--trans", "10", "--seconds", "1"]) == EXIT_WHY_NO_DRIVE
    assert capsys.readouterr().err.startswith("rtmu drive: this login (no user name) may not drive")


def test_server_killed_while_streaming_status_exits_3(capsys: pytest.CaptureFixture[str]) -> None:
    sent = [0]

    def numbers_then_die(side, args):  # type: ignore[no-untyped-def]
        sent[0] += 1
        if sent[0] > 3:
            server.kill(side)
            return None
        return [bytes(19)]

    with ServerThread(TestServer()) as server:
        server.handlers["updateNumbers"] = numbers_then_die
        code = main(
            ["status", f"127.0.0.1:{server.port}", "--interval", "20", "--timeout", "2", "--count", "50"]
        )
    assert code == EXIT_CONNECTION
    assert "closed" in capsys.readouterr().err


def _drive_process(sim: SimThread, pwfile: Path, *extra: str) -> subprocess.Popen[str]:
    args = [sys.executable, "-m", "rtmu", "drive", *login(sim, pwfile), "--trans", "80", "--seconds", "20"]
    args += extra
    # Its own process group, so that Ctrl-Z (SIGTSTP) really suspends it wherever the tests run.
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, process_group=0)
    if "--json" not in extra:
        assert proc.stdout is not None and proc.stdout.readline().startswith("before:")
    # A fresh interpreter, its guardian process and two logins first: generous on a loaded machine.
    eventually(lambda: sim.snapshot().trans_ratio == 80, timeout=20)
    return proc


def _stopped_by_us(sim: SimThread) -> bool:
    snap = sim.snapshot()
    return snap.trans_ratio == 0 and snap.mode_name == "stop" and snap.watchdog_stops == 0


@pytest.mark.parametrize(
    "sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGQUIT, signal.SIGUSR1]
)
def test_drive_ended_by_a_signal_stops_the_robot_and_exits_128_plus_n(
    sim: SimThread, pwfile: Path, sig: signal.Signals
) -> None:
    proc = _drive_process(sim, pwfile)
    try:
        proc.send_signal(sig)
        assert proc.wait(10) == 128 + sig
        out, err = proc.stdout.read(), proc.stderr.read()  # type: ignore[union-attr]
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert _stopped_by_us(sim)  # our zero ratios and stop, not the server's 2 s watchdog
    assert out.startswith("after:  x=") and out.count("\n") == 1  # the pose after the stop
    assert err == f"rtmu drive: interrupted by {sig.name}; the robot was stopped\n"


def test_ctrl_z_stops_the_robot_before_suspending_and_fg_does_not_drive_again(
    sim: SimThread, pwfile: Path
) -> None:
    proc = _drive_process(sim, pwfile)
    try:
        proc.send_signal(signal.SIGTSTP)
        eventually(lambda: _process_state(proc.pid) in ("T", "t"), timeout=5)  # suspended…
        eventually(lambda: _stopped_by_us(sim), timeout=5)  # …and its stop still reaches the robot
        assert _process_state(proc.pid) in ("T", "t")
        drives = sim.call(lambda: sim.server.robot.ratio_drives_received)  # type: ignore[union-attr]
        proc.send_signal(signal.SIGCONT)
        assert proc.wait(10) == 128 + signal.SIGTSTP
        assert proc.stdout.read().startswith("after:")  # type: ignore[union-attr]
        assert sim.call(lambda: sim.server.robot.received_ratios)[:2] == (0.0, 0.0)  # type: ignore[union-attr]
        assert sim.call(lambda: sim.server.robot.ratio_drives_received) <= drives + 1  # type: ignore[union-attr]
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert _stopped_by_us(sim)


def _process_state(pid: int) -> str:
    """The one-letter state of a process from /proc (``T`` = stopped); ``?`` once it is gone."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return "?"
    return stat.rpartition(")")[2].split()[0]


def test_drive_json_after_ctrl_c_says_it_was_interrupted(sim: SimThread, pwfile: Path) -> None:
    proc = _drive_process(sim, pwfile, "--json")
    try:
        proc.send_signal(signal.SIGINT)
        assert proc.wait(10) == 130
        obj = json.loads(proc.stdout.read())  # type: ignore[union-attr]
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert obj["interrupted"] == "SIGINT" and set(obj["after"]) == STATUS_KEYS and obj["seconds"] == 20


def test_drive_inside_arias_dead_zone_says_so_and_does_not_exit_0(
    sim: SimThread, pwfile: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 22 (say so) and issue 24 (asked to move and did not: never 0) both hold: a warning first,
    then the answer names the dead zone, with its own code."""
    before = sim.snapshot()
    assert main(["drive", *login(sim, pwfile), "--trans", "10", "--seconds", "0.5"]) == EXIT_WHY_DEAD_ZONE
    err = capsys.readouterr().err
    warning, _, answer = err.partition("the robot did not move: ")
    assert "inside ARIA's dead zone" in warning and "the robot will not move" in warning, err
    assert "inside ARIA's dead zone" in answer and "ask for more than 10 % translation" in answer, err
    assert "nothing RTMU can read says why" not in err
    after = sim.snapshot()
    assert (after.x, after.y) == (before.x, before.y), "ARIA's dead zone: it really did not move"
    assert main(["drive", *login(sim, pwfile), "--trans", "11", "--seconds", "0.3"]) == EXIT_OK
    assert "dead zone" not in capsys.readouterr().err

"""``rtmu replay`` and ``rtmu bridge`` as processes: their refusals, and a bridge serving until SIGTERM."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import time
from pathlib import Path

from recorder.foxglove_client import FoxgloveClient, twist
from recorder.simsession import ARENA
from rtmu.base.exit_codes import EXIT_BAD_FILE
from rtmu.recorder import topics
from rtmu.sim import SimConfig, SimThread

RTMU = [sys.executable, "-m", "rtmu"]


def rtmu(*args: str, timeout: float = 60) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*RTMU, *args], capture_output=True, text=True, timeout=timeout)


def test_replay_refuses_a_file_it_cannot_replay_before_any_window(tmp_path: Path) -> None:
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"\x89MCAP0\r\n" + b"\xff" * 64)
    done = rtmu("replay", str(junk))
    assert done.returncode == EXIT_BAD_FILE, done.stderr  # one table: a file that cannot be used
    assert "rtmu replay:" in done.stderr and "junk.mcap" in done.stderr
    missing = rtmu("replay", str(tmp_path / "none.mcap"))
    assert missing.returncode == 2 and "does not exist" in missing.stderr


def test_bridge_refuses_bad_options() -> None:
    assert rtmu("bridge", "127.0.0.1:1", "--foxglove", "--port", "70000").returncode == 2
    assert rtmu("bridge", "127.0.0.1:1").returncode == 2  # --foxglove is the only kind there is
    failed = rtmu("bridge", "127.0.0.1:1", "--foxglove", "--port", "0", "--timeout", "2")
    assert failed.returncode == 3, failed.stderr


def test_bridge_warns_when_driving_is_allowed_on_an_address_the_network_reaches() -> None:
    """192.0.2.1 (TEST-NET-1) is no address of this machine: the warning comes, then the bind fails."""
    args = ("bridge", "127.0.0.1:1", "--foxglove", "--timeout", "2")
    done = rtmu(*args, "--bind", "192.0.2.1", "--allow-drive")
    assert "WARNING: --allow-drive on 192.0.2.1" in done.stderr and "token" in done.stderr
    assert done.returncode != 0 and "cannot serve on 192.0.2.1" in done.stderr
    quiet = rtmu("bridge", "127.0.0.1:1", "--foxglove", "--port", "0", "--allow-drive", "--timeout", "2")
    assert "WARNING" not in quiet.stderr  # loopback: no warning
    watched = rtmu("bridge", "127.0.0.1:1", "--foxglove", "--bind", "192.0.2.1", "--timeout", "2")
    assert "WARNING" not in watched.stderr and "can watch the robot" in watched.stderr


def test_bridge_serves_poses_until_sigterm() -> None:
    with SimThread(SimConfig(port=0, map_path=ARENA, seed=1)) as sim:
        proc = subprocess.Popen(
            [*RTMU, "bridge", f"127.0.0.1:{sim.port}", "--foxglove", "--port", "0"],
            stderr=subprocess.PIPE,
            text=True,
        )
        try:
            assert proc.stderr is not None
            line = proc.stderr.readline()
            found = re.search(r"ws://127\.0\.0\.1:(\d+) \(no drive\)", line)
            assert found, line
            with FoxgloveClient(f"ws://127.0.0.1:{found.group(1)}") as client:
                client.until(lambda: bool(client.server_info))
                client.subscribe(topics.POSE, topics.STATUS)
                client.until(lambda: bool(client.of(topics.STATUS)), 10)
            proc.send_signal(signal.SIGTERM)
            assert proc.wait(10) == 128 + signal.SIGTERM  # as every command ended by a signal
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait(5)


def test_bridge_with_allow_drive_drives_with_its_guardian_and_stops_when_the_stream_ends() -> None:
    """The whole command: its guardian (a second login) lets a healthy drive go on; the stream's end stops."""
    with SimThread(SimConfig(port=0, seed=1)) as sim:
        proc = subprocess.Popen(
            [*RTMU, "bridge", f"127.0.0.1:{sim.port}", "--foxglove", "--ws-port", "0", "--allow-drive"],
            stderr=subprocess.PIPE,
            text=True,
        )
        try:
            assert proc.stderr is not None
            line = proc.stderr.readline()
            found = re.search(r"(ws://127\.0\.0\.1:\d+/\?token=[\w-]+) \(drive allowed from /cmd_vel", line)
            assert found, line
            assert "app.foxglove.dev" in proc.stderr.readline()
            with FoxgloveClient(found.group(1)) as client:
                client.until(lambda: bool(client.server_info))
                client.advertise(1, "/cmd_vel")
                start = sim.snapshot().x
                # The first drive waits until its guardian has logged in (a fresh process, cold on a
                # loaded machine): a stream held meanwhile then drives without a pause.
                armed = time.monotonic() + 20.0
                while sim.snapshot().trans_ratio == 0:
                    assert time.monotonic() < armed, "the stream never drove"
                    client.publish(1, twist(0.5))
                    client.pump(0.1)
                end = time.monotonic() + 2.0  # longer than the guardian's 0.4 s without a beat
                while time.monotonic() < end:
                    client.publish(1, twist(0.5))
                    client.pump(0.1)
                    assert sim.snapshot().trans_ratio > 0, "a drive stopped early"
                assert sim.snapshot().x > start + 300
                last = time.monotonic()
                while sim.snapshot().trans_ratio != 0:
                    assert time.monotonic() - last < 2.0, "the robot was never stopped"
                    time.sleep(0.01)
            proc.send_signal(signal.SIGTERM)
            assert proc.wait(10) == 128 + signal.SIGTERM  # as every command ended by a signal
            assert "guardian" not in proc.stderr.read().lower()  # it was there: no "not available"
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait(5)

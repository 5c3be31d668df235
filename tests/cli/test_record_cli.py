"""``rtmu record`` and ``rtmu decode FILE.mcap`` end to end, as processes, against the simulator."""

from __future__ import annotations

import json
import socket
import subprocess
import sys
from pathlib import Path

from recorder.mcapread import read, summary_counts
from recorder.simsession import ARENA
from rtmu.protocol.motion import MOTION_REQUESTS
from rtmu.recorder import topics
from rtmu.sim import SimConfig, SimThread

RTMU = [sys.executable, "-m", "rtmu"]


def rtmu(*args: str, timeout: float = 60) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*RTMU, *args], capture_output=True, text=True, timeout=timeout)


def test_record_then_decode_the_recording_like_a_capture(tmp_path: Path) -> None:
    out = tmp_path / "lab.mcap"
    with SimThread(SimConfig(port=0, map_path=ARENA, seed=1)) as sim:
        done = rtmu(
            "record", f"127.0.0.1:{sim.port}", "--out", str(out), "--seconds", "2", "--camera-hz", "4"
        )
    assert done.returncode == 0, done.stderr
    assert f"recording 127.0.0.1:{sim.port} to {out}" in done.stderr
    assert "0 dropped" in done.stderr
    counts = summary_counts(out)  # finished: it has its summary
    assert counts[topics.CAMERA] >= 4 and counts[topics.MAP] == 1 and counts[topics.STATUS] >= 1
    assert read(out).records(topics.STOPS) == [], "a recorder is an observer: it never stops the robot"

    decoded = rtmu("decode", "--json", str(out))
    assert decoded.returncode == 0, decoded.stderr
    lines = [json.loads(line) for line in decoded.stdout.splitlines()]
    packets = [p for p in lines if "dir" in p and p.get("kind") != "dropped"]
    names = [(p["dir"], p["name"]) for p in packets]
    assert names[0] == ("s2c", "INTRODUCTION") and ("c2s", "INTRODUCTION") in names
    # Our goodbye is the last thing we say; the server's bytes read after it (while the client waits
    # for the server to close, so the stop is not lost to a reset) are on the wire but not delivered.
    said = [n for n in names if n[0] == "c2s"]
    assert not {name for _, name in said} & MOTION_REQUESTS and said[-1] == ("c2s", "SHUTDOWN")
    assert said.count(("c2s", "SHUTDOWN")) == 1
    delivered = packets[: names.index(("c2s", "SHUTDOWN"))]
    pictures = [p for p in delivered if p["dir"] == "s2c" and p["name"] == "getPictureCam1"]
    assert len(pictures) == counts[topics.CAMERA], "every picture the session got is in the raw channel"
    assert all(p["checksum_ok"] for p in packets)
    assert all(p["time"] is not None and p["time"] >= 0 for p in packets)

    text = rtmu("decode", str(out))
    assert text.returncode == 0, text.stderr
    assert text.stdout.startswith(f"# {out.name}: mcap\n")
    assert f"conn 1: tcp client rtmu:0  server 127.0.0.1:{sim.port}" in text.stdout
    assert "dropped: nothing" in text.stdout


def test_record_without_a_server_fails_like_every_connecting_command(tmp_path: Path) -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]  # nothing listens here once the socket closes
    out = tmp_path / "none.mcap"
    done = rtmu("record", f"127.0.0.1:{port}", "--out", str(out), "--seconds", "1", "--timeout", "2")
    assert done.returncode == 3, done.stderr
    assert "refused" in done.stderr.lower()
    assert not out.exists(), "no file for a session that never began"


def test_decode_says_when_an_mcap_file_is_not_an_rtmu_recording(tmp_path: Path) -> None:
    import foxglove

    path = tmp_path / "other.mcap"
    with foxglove.open_mcap(path, context=foxglove.Context()):
        pass
    done = rtmu("decode", str(path))
    assert done.returncode == 0
    assert "no RTMU raw channel" in done.stderr and "no ArNetworking packets found" in done.stdout


def test_record_ends_at_sigterm_with_a_finished_file(tmp_path: Path) -> None:
    import signal
    import time

    out = tmp_path / "term.mcap"
    with SimThread(SimConfig(port=0, seed=1)) as sim:
        proc = subprocess.Popen(
            [*RTMU, "record", f"127.0.0.1:{sim.port}", "--out", str(out)],
            stderr=subprocess.PIPE,
            text=True,
        )
        try:
            deadline = time.monotonic() + 15
            partial = out.with_name(out.name + ".partial")  # written beside it until the end
            while not (partial.exists() and partial.stat().st_size > 2000):
                assert time.monotonic() < deadline and proc.poll() is None
                time.sleep(0.05)
            proc.send_signal(signal.SIGTERM)
            _, err = proc.communicate(timeout=15)
        finally:
            if proc.poll() is None:
                proc.kill()
    assert proc.returncode == 128 + signal.SIGTERM, err  # as every command ended by a signal
    assert not partial.exists()
    counts = summary_counts(out)
    assert counts[topics.STATUS] >= 1 and counts["/aria/raw/s2c"] > 0

"""A recording survives its process: SIGKILL leaves a readable file, a full disk ends the recording.

Both run ``rtmu record`` as a real process against the simulator on loopback. The
disk fills for real: the process's file size limit (RLIMIT_FSIZE, with SIGXFSZ
ignored) makes the kernel refuse the write with EFBIG, as a full disk refuses with
ENOSPC: ``rtmu record`` says so once and ends (exit 17) with what it had. The in-process
test shows the window's side: the notice reaches the view and the session goes on.
"""

from __future__ import annotations

import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from mcap.exceptions import McapError

from patience import PATIENCE
from rtmu.base.exit_codes import EXIT_SIZE_LIMIT
from rtmu.base.notices import Kind
from rtmu.capture.recorded import RAW_TOPICS
from rtmu.model.observables import Phase
from rtmu.recorder import Limits, topics
from rtmu.sim import SimConfig, SimThread
from rtmu.values.intents import RequestPicture

from .mcapread import read, summary_counts
from .simsession import ARENA, recorded_session

RECORD = [sys.executable, "-m", "rtmu", "record"]
DISK = 120_000
"""Bytes the "disk" holds: the first chunks (the map, a Pioneer's laser at 5 Hz, two pictures a
second) and a few seconds more fill it."""


def sim_bytes_in(sim: SimThread) -> int:
    return int(sim.call(lambda: sum(s.bytes_in for s in sim.server.sessions)))


def wait_growing(path: Path, size: int, timeout: float = 15.0) -> None:
    deadline = time.monotonic() + timeout * PATIENCE
    while not (path.exists() and path.stat().st_size > size):
        assert time.monotonic() < deadline, f"{path} did not grow past {size} bytes"
        time.sleep(0.05)


def test_a_recording_killed_mid_session_reads_up_to_its_last_second(tmp_path: Path) -> None:
    named = tmp_path / "killed.mcap"
    out = tmp_path / "killed.mcap.partial"  # until it ends, the recording is written beside its name
    with SimThread(SimConfig(port=0, map_path=ARENA, seed=1)) as sim:
        proc = subprocess.Popen(
            [*RECORD, f"127.0.0.1:{sim.port}", "--out", str(named), "--camera-hz", "5"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
        )
        try:
            wait_growing(out, 20_000)
            time.sleep(3.0)
            killed_at = time.time_ns()
            proc.send_signal(signal.SIGKILL)
            proc.wait(5)
        finally:
            if proc.poll() is None:
                proc.kill()
    assert proc.returncode == -signal.SIGKILL
    assert not named.exists()
    with pytest.raises(McapError):
        summary_counts(out)  # no summary: the process never finished the file
    got = read(out)
    counts = got.counts()
    assert counts[RAW_TOPICS["s2c"]] > 10 and counts[RAW_TOPICS["c2s"]] > 5
    assert counts[topics.STATUS] >= 1 and counts[topics.CAMERA] >= 5 and counts[topics.MAP] == 1
    last = max(m.log_time for m in got.messages)
    assert killed_at - last < 2.5e9, f"lost {(killed_at - last) / 1e9:.1f} s (flushed every second)"
    decoded = subprocess.run(
        [sys.executable, "-m", "rtmu", "decode", "--json", str(out)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert decoded.returncode == 0, decoded.stderr
    assert '"name":"updateNumbers"' in decoded.stdout


def _small_disk() -> None:
    """In the child: files may not grow past 40 kB, and a write past it fails instead of killing us."""
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (DISK, DISK))


def test_a_full_disk_ends_the_recording_once_and_keeps_what_came_before(tmp_path: Path) -> None:
    out = tmp_path / "full.mcap"
    partial = tmp_path / "full.mcap.partial"
    with SimThread(SimConfig(port=0, map_path=ARENA, seed=1)) as sim:
        proc = subprocess.Popen(
            [*RECORD, f"127.0.0.1:{sim.port}", "--out", str(out), "--fps", "2", "--seconds", "60"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            preexec_fn=_small_disk,
        )
        try:
            wait_growing(partial, 10_000)
            _, err = proc.communicate(timeout=30)  # it ends by itself, long before --seconds
        finally:
            if proc.poll() is None:
                proc.kill()
    assert proc.returncode == EXIT_SIZE_LIMIT, err
    assert err.count("writing full.mcap.partial failed (File too large)") == 1, err  # said once
    assert "the recording ends here" in err
    assert out.stat().st_size <= DISK and not partial.exists()
    got = read(out)
    assert got.counts()[RAW_TOPICS["s2c"]] > 10, "what came before the failure reads"


def test_the_window_hears_that_its_recording_stopped_and_keeps_its_robot(tmp_path: Path) -> None:
    """The size limit ends the recording: one RECORDING notice to the view, the status keeps coming."""
    with recorded_session(tmp_path) as (session, ui, view, _sim):
        recorder = session.recorder
        assert recorder is not None
        recording = recorder.recordings[0]
        recording.limits = Limits(max_bytes=30_000)  # the map and a few seconds of status fill it
        ui.wait_for(lambda: Kind.RECORDING in view.kinds, timeout=15)
        assert "size limit" in view.texts()[view.kinds.index(Kind.RECORDING)]
        assert recording.stopped is not None
        before = session.state.camera.value
        session.controller.ask(RequestPicture())  # the session goes on: a new picture arrives
        ui.wait_for(lambda: session.state.camera.value is not before, timeout=5)
        age = session.runner.status_age()
        assert age is not None and age < 1.0, "status still streams in"
        assert session.state.connection.value.phase is Phase.CONNECTED
        assert view.kinds.count(Kind.RECORDING) == 1
    got = read(recording.path)
    assert got.counts()[RAW_TOPICS["s2c"]] > 0
    assert summary_counts(recording.path), "a recording ended by its limit is finished at once"

"""The recorder's writer leaves the interpreter to the threads that drive: a bounded share of the CPU,
a bounded number of raw bytes waiting, the surplus of a flood dropped and counted."""

from __future__ import annotations

import os
import threading
import time
from pathlib import Path

import pytest

from rtmu.capture.recorded import RAW_TOPICS, S2C
from rtmu.recorder import Limits, Recording
from rtmu.recorder.duty import DEBT_MAX, REST_MIN, DutyCycle
from rtmu.recorder.items import RawChunk

from .mcapread import summary_counts

CHUNK = 64 * 1024


def test_work_is_paid_for_with_rest_in_proportion() -> None:
    duty = DutyCycle(0.2)
    assert duty.worked(0.001) == pytest.approx(0.004)  # 1 ms of work at a fifth: 4 ms of rest
    assert duty.worked(REST_MIN / 10) == 0.0  # too little to sleep for: owed, not forgotten
    assert duty.worked(REST_MIN / 4) == pytest.approx(REST_MIN * 0.4 + REST_MIN)
    assert duty.worked(10.0) == DEBT_MAX  # one slow write never silences the writer for long
    assert duty.rested == pytest.approx(0.004 + REST_MIN * 1.4 + DEBT_MAX)
    with pytest.raises(ValueError):
        DutyCycle(0.0)


def _chunk(n: int) -> RawChunk:
    return RawChunk(1, S2C, os.urandom(CHUNK), time.time_ns() + n)


def test_raw_bytes_waiting_for_the_writer_are_bounded(tmp_path: Path) -> None:
    """Before the writer runs at all: 1 MB of room takes 16 reads of 64 KB; the rest is dropped, counted."""
    recording = Recording(tmp_path / "bounded.mcap", limits=Limits(queue_bytes=1 << 20))
    accepted = sum(recording.submit(_chunk(n)) for n in range(40))
    assert (accepted, recording.dropped) == (16, 24)
    recording.start()
    recording.close()
    assert summary_counts(recording.path)[RAW_TOPICS[S2C]] == 16
    assert recording.submit(_chunk(99)) is False  # closed


def _cpu_seconds(tid: int) -> float:
    with open(f"/proc/self/task/{tid}/schedstat", "rb") as f:
        return int(f.read().split()[0]) / 1e9


def test_a_flood_of_raw_chunks_takes_at_most_a_share_of_the_cpu(tmp_path: Path) -> None:
    """A producer offers incompressible 64 KB reads as fast as it can for a second: the writer rests
    (its CPU time stays near its fifth of the time, whatever the machine does meanwhile — a busy
    machine gives it less, never more), and what it could not take was dropped and counted."""
    if not Path(f"/proc/self/task/{threading.get_native_id()}/schedstat").exists():
        pytest.skip("needs /proc/self/task/*/schedstat")
    blocks = [os.urandom(CHUNK) for _ in range(16)]
    recording = Recording(tmp_path / "flood.mcap").start()
    deadline = time.monotonic() + 10
    while recording._thread.native_id is None and time.monotonic() < deadline:
        time.sleep(0.01)
    writer = recording._thread.native_id
    assert writer is not None
    before, started = _cpu_seconds(writer), time.monotonic()
    n = 0
    while time.monotonic() - started < 1.0:
        recording.submit(RawChunk(1, S2C, blocks[n % 16], time.time_ns()))
        n += 1
    share = (_cpu_seconds(writer) - before) / (time.monotonic() - started)
    recording.close()
    assert share < 0.35, f"the writer took {share:.0%} of a CPU"
    assert recording.duty.rested > 0.1
    assert recording.dropped > 0
    assert summary_counts(recording.path)[RAW_TOPICS[S2C]] == n - recording.dropped

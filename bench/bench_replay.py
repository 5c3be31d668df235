"""Replay (``rtmu replay``): how fast a recording is read and how fast a backward seek rebuilds the state.

A session against the simulator (arena map, 10 Hz status, sonar, the robot driving in
circles, 2 camera pictures a second) is recorded for ``SECONDS``; then:

* ``replay.load_ms``: reading the file for replay (the connection's server bytes, their gates,
  the pictures) — baseline: only iterating the file's messages with the ``mcap`` reader.
* ``replay.rebuild_x_realtime``: a seek from the start to the end as fast as the client takes
  the bytes (what a backward seek to the end costs; the window's worst case), in recording
  seconds per wall second — baseline: the same bytes through the framing decoder alone.
* ``replay.rebuild_ms_per_min``: the same as milliseconds per minute of recording.
* ``replay.gate_fallbacks``: chunks that went on without the client packet they waited for
  (should be 0: every request the replay makes was answered in order).
* ``replay.x1_lag_ms_p95``: playing at x1, how late (wall clock) each chunk is handed over
  after its recorded time came.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

from bench.common import Result
from rtmu.client.runner import ClientRunner
from rtmu.package_data import project_map
from rtmu.protocol.decoder import PacketDecoder
from rtmu.recorder import Recorder, RecorderConfig
from rtmu.recorder.replay import REPLAY_CONFIG, PacedLink, Replayer
from rtmu.recorder.replay_file import load
from rtmu.sim import SimConfig, SimThread
from rtmu.values.intents import RequestPicture
from rtmu.values.target import Target

ARENA = project_map("arena.map")
SECONDS = float(os.environ.get("RTMU_REPLAY_BENCH_SECONDS", "30"))


def record(out: Path) -> None:
    with SimThread(SimConfig(port=0, map_path=ARENA, seed=2)) as sim:
        recorder = Recorder(RecorderConfig(out.parent, path=out, keep_days=0))
        runner = ClientRunner(opener=recorder.opener())
        recorder.attach(runner)
        runner.start()
        try:
            runner.connect(Target("127.0.0.1", sim.port, auto_reconnect=False)).result(15)
            end = time.monotonic() + SECONDS
            next_picture = 0.0
            while time.monotonic() < end:
                sim.call(lambda: sim.server.world.ratio_drive(40.0, 25.0, 60.0))  # type: ignore[union-attr]
                if time.monotonic() >= next_picture:
                    runner.send(RequestPicture())
                    next_picture = time.monotonic() + 0.5
                time.sleep(0.1)
            sim.call(lambda: sim.server.world.stop())  # type: ignore[union-attr]
        finally:
            runner.close()
            recorder.close()


def read_only(path: Path) -> None:
    from mcap.reader import NonSeekingReader

    with path.open("rb") as f:
        for _ in NonSeekingReader(f).iter_messages(log_time_order=False):
            pass


def rebuild(path: Path) -> tuple[float, PacedLink]:
    replayer = Replayer(load(path))
    runner = ClientRunner(opener=replayer.open, config=REPLAY_CONFIG, clock=replayer.clock.seconds)
    runner.start()
    try:
        replayer.clock.seek(replayer.clock.end_ns)
        t0 = time.perf_counter()
        runner.connect(Target("replay", 0, auto_reconnect=False))
        while replayer.link is None or not replayer.link.exhausted:
            time.sleep(0.002)
        elapsed = time.perf_counter() - t0
        link = replayer.link
    finally:
        runner.close()
    return elapsed, link


def x1_lag(path: Path, seconds: float = 8.0) -> list[float]:
    replayer = Replayer(load(path))
    lags: list[float] = []
    runner = ClientRunner(opener=replayer.open, config=REPLAY_CONFIG, clock=replayer.clock.seconds)
    runner.start()
    try:
        replayer.clock.play()
        runner.connect(Target("replay", 0, auto_reconnect=False))
        end = time.monotonic() + seconds
        seen = 0
        while time.monotonic() < end:
            link = replayer.link
            if link is not None and link.position > seen:
                now = replayer.clock.now_ns()
                lags.append((now - link.delivered_ns) / 1e6)
                seen = link.position
            time.sleep(0.001)
    finally:
        runner.close()
    return lags


def run() -> list[Result]:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "bench.mcap"
        record(path)
        recorded = load(path)
        minutes = recorded.duration_ns / 60e9
        t0 = time.perf_counter()
        load(path)
        load_s = time.perf_counter() - t0
        t0 = time.perf_counter()
        read_only(path)
        read_s = time.perf_counter() - t0
        decoder = PacketDecoder()
        t0 = time.perf_counter()
        for chunk in recorded.chunks:
            decoder.feed(chunk.data)
        decode_s = time.perf_counter() - t0
        elapsed, link = min((rebuild(path) for _ in range(3)), key=lambda r: r[0])
        lags = sorted(x1_lag(path))
        p95 = lags[int(0.95 * (len(lags) - 1))] if lags else float("nan")
        duration_s = recorded.duration_ns / 1e9
    return [
        Result("replay.load_ms", load_s * 1000, "ms", baseline=read_s * 1000),
        Result("replay.rebuild_x_realtime", duration_s / elapsed, "x", baseline=duration_s / decode_s),
        Result("replay.rebuild_ms_per_min", elapsed * 1000 / minutes, "ms/min"),
        Result("replay.gate_fallbacks", float(link.fallbacks), "chunks"),
        Result("replay.x1_lag_ms_p95", p95, "ms"),
    ]


if __name__ == "__main__":
    for r in run():
        print(r.as_json())

"""Live video on the wire: picture requests per new frame, against a camera slower than asked.

The simulator runs in its own process (``bench.video_server``: office map, 320x240 camera making at
most :data:`CAMERA_HZ` new frames a second — ARIA's video forwarder polls its camera ten times a
second — the robot turning so each new frame really differs). ``client.video_feed.VideoFeed`` (what
``rtmu video`` and the window's live video run) asks it for pictures at ``--fps`` 30 and 15 for
:data:`SECONDS` each (after :data:`WARM_UP_S` in which the pacer learns the camera's period), with
its :class:`~rtmu.client.video_feed.FramePacer`, then the same with the pacing of before (ask at the
frame-rate setting, a quarter of that interval after a repeat), turn about. Frames carry the
simulator's render stamp, so ages are end to end.

* ``video.pace.requests_per_new_frame.fps{30,15}``: requests sent ÷ new frames received (target
  ≤ 1.2; a repeat is a whole picture sent again over the robot's Wi-Fi). Baseline: the old pacing.
* ``video.pace.requests_per_s.fps{30,15}`` and ``video.pace.new_frames_per_s.fps{30,15}``.
* ``video.pace.age_ms_p50.fps{30,15}`` / ``.p95``: render stamp → arrival of each new frame (target:
  no higher than the old pacing's).
* ``video.pace.kbytes_per_s.fps{30,15}``: picture bytes received per second.
"""

from __future__ import annotations

import asyncio
import statistics
import subprocess
import sys
from pathlib import Path

from bench.common import Result, end_process
from rtmu.client.connection import AriaClient
from rtmu.client.video_feed import FramePacer, LiveFrame, VideoFeed, video_source
from rtmu.values.target import Target

CAMERA_HZ = 10.0
SIZE = "320x240"
SECONDS = 8.0
WARM_UP_S = 3.0
"""Played before the figures start: the pacer learns the camera's period once per session."""
ROUNDS = 2
REPO = Path(__file__).resolve().parents[1]


class QuarterRetry(FramePacer):
    """The pacing of before (the baseline): every request at the frame-rate setting, and after a
    repeat again a quarter of that interval later."""

    def after(self, sent: float, outcome: str, min_interval: float) -> float:
        self.requests += 1
        self.new_frames += outcome == "new"
        return sent + (min_interval / 4 if outcome == "repeat" else min_interval)


async def play(port: int, fps: float, pacer: FramePacer) -> dict[str, float]:
    client = AriaClient()
    await client.connect(Target("127.0.0.1", port))
    sizes: list[int] = []
    try:
        source = video_source(client)

        def on_frame(frame: LiveFrame) -> None:
            sizes.append(len(frame.jpeg))
            feed.shown(frame.sequence)

        feed = VideoFeed(client, source, on_frame, fps=fps, max_pending=1)
        feed.pacer = pacer
        await feed.run(WARM_UP_S)  # the camera's period learned (once per session), the robot turning
        pacer.requests = pacer.new_frames = 0
        sizes.clear()
        feed.stats.ages_ms.clear()
        loop = asyncio.get_running_loop()
        t0 = loop.time()
        await feed.run(SECONDS)
        elapsed = loop.time() - t0
        ages = list(feed.stats.ages_ms)
        repeat_bytes = statistics.fmean(sizes) if sizes else 0.0
        return {
            "requests": pacer.requests / elapsed,
            "new": pacer.new_frames / elapsed,
            "per_new": pacer.requests / max(pacer.new_frames, 1),
            "age_p50": statistics.median(ages) if ages else float("nan"),
            "age_p95": statistics.quantiles(ages, n=20)[-1] if len(ages) > 1 else float("nan"),
            "kbytes": pacer.requests * repeat_bytes / 1000.0 / elapsed,  # a repeat is a whole picture
        }
    finally:
        await client.disconnect()


def run() -> list[Result]:
    server = subprocess.Popen(
        [sys.executable, "-m", "bench.video_server", SIZE, str(CAMERA_HZ)],
        cwd=REPO,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    results: list[Result] = []
    try:
        assert server.stdout is not None and server.stdin is not None
        port = int(server.stdout.readline().split()[1])
        for fps in (30.0, 15.0):
            ours: list[dict[str, float]] = []
            old: list[dict[str, float]] = []
            for _ in range(ROUNDS):  # turn about: a burst of load lands on one run, not on one side
                ours.append(asyncio.run(play(port, fps, FramePacer())))
                old.append(asyncio.run(play(port, fps, QuarterRetry())))
            tag = f"fps{fps:.0f}"
            new, base = ({k: statistics.median(r[k] for r in runs) for k in runs[0]} for runs in (ours, old))
            results += [
                Result(
                    f"video.pace.requests_per_new_frame.{tag}", new["per_new"], "requests", base["per_new"]
                ),
                Result(f"video.pace.requests_per_s.{tag}", new["requests"], "1/s", base["requests"]),
                Result(f"video.pace.new_frames_per_s.{tag}", new["new"], "1/s", base["new"]),
                Result(f"video.pace.age_ms_p50.{tag}", new["age_p50"], "ms", base["age_p50"]),
                Result(f"video.pace.age_ms_p95.{tag}", new["age_p95"], "ms", base["age_p95"]),
                Result(f"video.pace.kbytes_per_s.{tag}", new["kbytes"], "kB/s", base["kbytes"]),
            ]
        server.stdin.close()
        server.wait(20)
    finally:
        if server.poll() is None:
            end_process(server)
    return results

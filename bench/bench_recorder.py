"""The flight recorder's price: CPU of recording a session against the same session unrecorded, and disk.

One simulator (10 Hz status, sonar, 640×480 camera pictures) serves two client
processes in turn, each the window's client core driving in circles and asking
for 10 pictures a second: one records (``rtmu.recorder``), one does not. Each
reports its own CPU time (all threads), so the simulator's work is not counted.

* ``recorder.cpu_pct_of_core``: CPU of the recording client, % of one core
  (baseline: the same client unrecorded; ratio = with / without).
* ``recorder.cost_pct_of_core``: the difference — what recording costs (target ≤ 5 %).
* ``recorder.mb_per_hour``: what the measured part added to the file, extrapolated to one hour
  (the map, written once before, left out). The simulator's pictures are small (``picture_kb``);
* ``recorder.mb_per_hour_40kb_camera``: the same with the pictures a real 640×480 camera sends
  (~40 kB JPEGs at 10/s; JPEG does not compress further): ``mb_per_hour_no_camera`` (the same
  session recorded without pictures, measured) + 40 kB × 10/s. A picture
  is in the file twice (raw bytes and CompressedImage), but both land in one zstd chunk, which
  stores the second copy as a back-reference (100 random 40 kB pictures written twice: 4.0 MB).
* ``recorder.submit_us``: what one item costs the thread that produces it (the network
  loop that sends the stops): a timestamp and a non-blocking queue put.
* ``recorder.max_loop_lag_ms``: the network loop's worst heartbeat lag while recording
  (baseline: unrecorded).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench.common import Result, best_time
from rtmu.package_data import project_map
from rtmu.recorder import Limits, Recording, topics
from rtmu.recorder.items import Event
from rtmu.sim import SimConfig, SimThread

REPO = Path(__file__).resolve().parents[1]
ARENA = project_map("arena.map")
SECONDS = float(os.environ.get("RTMU_RECORDER_BENCH_SECONDS", "20"))
CAMERA_HZ = 10.0


def client(port: int, out: str, camera_hz: float = CAMERA_HZ) -> dict[str, float]:
    cmd = [sys.executable, "-m", "bench.recorder_client", str(port), str(SECONDS), str(camera_hz), out]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=SECONDS + 120, cwd=REPO)
    if done.returncode != 0:
        raise RuntimeError(f"recorder client failed: {done.stderr[-2000:]}")
    return dict(json.loads(done.stdout.splitlines()[-1]))


def submit_cost() -> float:
    """Seconds per ``Recording.submit`` of a small item (the producer's whole share)."""
    with tempfile.TemporaryDirectory() as tmp:
        recording = Recording(Path(tmp) / "s.mcap", limits=Limits(queue_items=1 << 20)).start()
        item = Event(topics.NOTICES, {"text": "x"}, time.time_ns())
        try:
            return best_time(lambda: recording.submit(item), repeat=5, min_seconds=0.1)
        finally:
            recording.close(30)


def run() -> list[Result]:
    with tempfile.TemporaryDirectory() as tmp, SimThread(SimConfig(port=0, map_path=ARENA, seed=1)) as sim:
        sim.call(lambda: setattr(sim.server, "video_size", (640, 480)))
        off = client(sim.port, "-")
        on = client(sim.port, str(Path(tmp) / "bench.mcap"))
        still = client(sim.port, str(Path(tmp) / "no-camera.mcap"), camera_hz=0.0)
    if on.get("stopped") or on.get("dropped"):
        raise RuntimeError(f"the recording did not keep up: {on}")
    pct_on = 100.0 * on["cpu_s"] / on["wall_s"]
    pct_off = 100.0 * off["cpu_s"] / off["wall_s"]
    per_hour = on["bytes"] / on["wall_s"] * 3600.0 / 1e6
    picture_kb = on["picture_bytes"] / max(1, on["pictures"]) / 1e3
    no_camera = still["bytes"] / still["wall_s"] * 3600.0 / 1e6
    real_camera = no_camera + 40e3 * CAMERA_HZ * 3600.0 / 1e6
    print(
        f"recorder: {on['pictures']} pictures ({picture_kb:.1f} kB each), {on['items']} items, "
        f"{on['bytes'] / 1e6:.2f} MB in "
        f"{on['wall_s']:.1f} s; CPU {pct_on:.1f} % vs {pct_off:.1f} % unrecorded",
        file=sys.stderr,
    )
    return [
        Result("recorder.cpu_pct_of_core", pct_on, "% of a core", pct_off),
        Result("recorder.cost_pct_of_core", pct_on - pct_off, "% of a core"),
        Result("recorder.mb_per_hour", per_hour, "MB"),
        Result("recorder.picture_kb", picture_kb, "kB"),
        Result("recorder.mb_per_hour_no_camera", no_camera, "MB"),
        Result("recorder.mb_per_hour_40kb_camera", real_camera, "MB"),
        Result("recorder.submit_us", submit_cost() * 1e6, "us"),
        Result("recorder.max_loop_lag_ms", on["max_loop_lag_s"] * 1000, "ms", off["max_loop_lag_s"] * 1000),
    ]

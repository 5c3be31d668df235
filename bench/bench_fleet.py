"""Many robots in one window: 1, 5 and 20 simulated robots at 10 Hz status each.

For each fleet size the simulators run in one process (``bench.fleet_sims``: every robot
wandering on the office map, so every status moves it) and the real window in another
(``bench.fleet_window``, on its own Xvfb), connected to all of them over loopback; after
every robot has its map and status, 10 s are measured:

* ``fleet.frame_ms.{1,5,20}_robots.{p50,p95}`` (ms): the map stage's draw time per frame,
  every robot and its trail drawn (target p95 ≤ 8 ms). Baseline of the 5- and 20-robot
  figures: the 1-robot p95 of the same run.
* ``fleet.updates_per_s_min.{1,5,20}_robots`` (1/s): the slowest robot's on-screen update
  rate — frames that showed a status of it not shown before (target ≥ 5/s each; the
  status is sent at 10 Hz).
* ``fleet.cpu_cores.{1,5,20}_robots`` (cores): CPU seconds per second of the window process
  and its children (the guardian processes), simulators excluded (target < 1). Its
  ``baseline`` is the window process alone, without the guardians.
* ``fleet.ready_s.{1,5,20}_robots`` (s): window start until every robot has its status and
  its map.
* ``fleet.map_downloads.{1,5,20}_robots``: map downloads at start-up — the robots share one map
  file, so one session downloads it and the others take it (``mapcache.SharedMaps``; without
  it: one per robot).

Needs Xvfb (started here when ``DISPLAY`` is unset); without one the figures are skipped.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import subprocess
import sys
from pathlib import Path

from bench.common import Result, end_process, start_xvfb

SIZES = (1, 5, 20)
SECONDS = 10.0
REPO = Path(__file__).resolve().parents[1]


@contextlib.contextmanager
def _display():  # type: ignore[no-untyped-def]
    if os.environ.get("DISPLAY"):
        yield os.environ["DISPLAY"]
        return
    proc, display = start_xvfb()
    try:
        yield display
    finally:
        end_process(proc)


@contextlib.contextmanager
def _sims(count: int, *, wander: bool = True):  # type: ignore[no-untyped-def]
    still = [] if wander else ["--still"]
    proc = subprocess.Popen([sys.executable, "-m", "bench.fleet_sims", str(count), *still], cwd=REPO,
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)  # fmt: skip
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        if not line.startswith("PORTS "):
            raise RuntimeError(f"the simulators did not start: {line!r}")
        yield [int(p) for p in line.split()[1:]]
    finally:
        end_process(proc)


def measure(count: int, display: str) -> dict[str, float]:
    """One fleet size: the window process's JSON figures."""
    env = dict(os.environ, DISPLAY=display, GSK_RENDERER="cairo", NO_AT_BRIDGE="1", GDK_BACKEND="x11")
    with _sims(count) as ports:
        out = subprocess.run(
            [sys.executable, "-m", "bench.fleet_window", str(SECONDS), *map(str, ports)],
            cwd=REPO, env=env, capture_output=True, text=True, timeout=900,
        )  # fmt: skip
    found = re.search(r"^RESULT (.*)$", out.stdout, re.MULTILINE)
    if found is None:
        raise RuntimeError(f"the window gave no figures (exit {out.returncode}): {out.stderr[-2000:]}")
    return dict(json.loads(found.group(1)))


def run() -> list[Result]:
    try:
        with _display() as display:
            figures = {n: measure(n, display) for n in SIZES}
    except FileNotFoundError:
        print("# fleet: no Xvfb: figures skipped", file=sys.stderr)
        return []
    one = figures[1]["frame_ms_p95"]
    results = []
    for n, f in figures.items():
        tag = f"{n}_robots"
        base = None if n == 1 else one
        results += [
            Result(f"fleet.frame_ms.{tag}.p50", f["frame_ms_p50"], "ms"),
            Result(f"fleet.frame_ms.{tag}.p95", f["frame_ms_p95"], "ms", base),
            Result(f"fleet.updates_per_s_min.{tag}", f["updates_per_s_min"], "1/s"),
            Result(f"fleet.cpu_cores.{tag}", f["cpu"], "cores", f.get("cpu_window")),
            Result(f"fleet.ready_s.{tag}", f["ready_s"], "s"),
            Result(f"fleet.map_downloads.{tag}", f["map_downloads"], "downloads"),
        ]
    return results

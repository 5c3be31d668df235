"""What ``base.heap.settle`` buys: the length of a full garbage-collector pass, before and after.

A full (generation 2) pass holds the interpreter lock while it walks every tracked object, so every
thread of the process — the simulator's status sender, the window's network loop — stands still
for it. Each figure is measured in a fresh process (the heap as the program has it):

* ``heap.full_pass_ms.sim_office`` (ms): a simulator serving the office map (its world, map and
  protocol tables built, as ``rtmu sim`` has them when it starts serving), median of
  :data:`PASSES` forced full passes after :func:`rtmu.base.heap.settle`. Baseline: the same
  process's passes before it. Nothing is made in between, so the figure after is the pass's own
  cost; in a running program a pass then walks only what was made since.
* ``heap.full_pass_ms.window_modules`` (ms): the same for a process that has imported what the
  window imports (the client core, the map model, the GTK views); the window settles once it is
  shown. Baseline: before.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from bench.common import Result

PASSES = 7
REPO = Path(__file__).resolve().parents[1]

_CHILD = r"""
import gc, json, statistics, sys, time

def passes(n):
    out = []
    for _ in range(n):
        t = time.perf_counter(); gc.collect(); out.append((time.perf_counter() - t) * 1000)
    return statistics.median(out)

kind, n = sys.argv[1], int(sys.argv[2])
keep = []
if kind == "sim":
    from rtmu.package_data import project_map
    from rtmu.sim import SimServer
    from rtmu.sim.config import SimConfig
    keep.append(SimServer(SimConfig(port=0, realtime=False, map_path=project_map("office.map"))))
else:
    import rtmu.ui.application, rtmu.client.runner, rtmu.mapfile  # noqa: F401  (what the window imports)
from rtmu.base.heap import settle
before = passes(n)
frozen = settle()
after = passes(n)
print(json.dumps({"before": before, "after": after, "frozen": frozen}))
"""


def _measure(kind: str) -> dict[str, float]:
    env = dict(
        os.environ,
        PYTHONPATH=os.pathsep.join(p for p in (str(REPO / "src"), os.environ.get("PYTHONPATH")) if p),
    )
    env.setdefault("GDK_BACKEND", "x11")  # importing the views needs no display; nothing is shown
    done = subprocess.run(
        [sys.executable, "-c", _CHILD, kind, str(PASSES)],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    if done.returncode != 0:
        raise RuntimeError(f"heap bench child ({kind}) failed: {done.stderr[-400:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def run() -> list[Result]:
    results = []
    for kind, name in (("sim", "sim_office"), ("window", "window_modules")):
        m = _measure(kind)
        print(f"# heap {name}: {m['frozen']:.0f} objects frozen", file=sys.stderr)
        results.append(Result(f"heap.full_pass_ms.{name}", m["after"], "ms", m["before"]))
    return results

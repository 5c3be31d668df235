"""Live map changes on the generated 1 M-point building: from Apply to the client holding the new map.

* ``mapedit.apply_to_reloaded_s.million``: one goal added as the window's Apply will add it — the
  draft's change sent as one ``processMapChanges`` series guarded by ``getMapId``
  (:func:`rtmu.client.map_changes.send_changes`), the verdict and ``mapUpdated`` awaited, then the
  whole map downloaded again (``getMapBinary``) and converted — against a real-time simulator on its
  own thread serving ``generate_map(1_000_000, 5_000, seed=3)``. Median of 3. Baseline: a plain full
  download of the same map (``download_map``) in the same run, median of 3: the part of Apply no map
  change can avoid.
* ``mapedit.apply_to_verdict_s.million``: from the first packet sent to the verdict (the simulator
  applies the set, writes the new map's text, its MD5 and its world on a worker thread). Same
  baseline.
* ``mapedit.window_apply_to_redrawn_s.million``: the same change made in the real window
  (``bench.mapedit_window``, its own process under a private Xvfb): from Apply in Server ▸ Edit the
  map… to the map stage's first complete frame of the reloaded map — what the operator waits for.
  Median of 3. Baseline: ``apply_to_reloaded`` above, the client alone, in the same run: the
  ratio is what the window adds (decoding off the loop, tiles, the frame). Skipped with a note
  without Xvfb.
"""

from __future__ import annotations

import asyncio
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench.common import Result, as_installed, end_process, start_xvfb
from rtmu.client.connection import AriaClient
from rtmu.client.map_changes import ChangeWatch, map_id, object_change_set, send_changes
from rtmu.client.mapload import download_map
from rtmu.mapedit import MapDraft
from rtmu.mapfile import write_map
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.mapgen import generate_map
from rtmu.values.target import Target

REPEAT = 3
TIMEOUT = 60.0


async def _measure(port: int) -> tuple[list[float], list[float], list[float]]:
    client = AriaClient()
    await client.connect(Target("127.0.0.1", port), timeout=TIMEOUT)
    try:
        downloads: list[float] = []
        for _ in range(REPEAT):
            t0 = time.perf_counter()
            base = await download_map(client, timeout=TIMEOUT)
            downloads.append(time.perf_counter() - t0)
        assert base.data is not None
        watch = ChangeWatch()
        watch.subscribe(client)
        verdicts: list[float] = []
        reloads: list[float] = []
        for i in range(REPEAT):
            draft = MapDraft(base.data.objects)
            draft.add_goal(f"Bench {i}", 1000 + i, 1000, 90)
            changes = object_change_set(draft.change(), base.data)
            guard = await map_id(client, TIMEOUT)
            t0 = time.perf_counter()
            verdict = await send_changes(client, changes, watch, guard=guard, timeout=TIMEOUT)
            t1 = time.perf_counter()
            if not verdict.applied:
                raise RuntimeError(f"the simulator refused the bench's change: {verdict.words}")
            base = await download_map(client, timeout=TIMEOUT)
            t2 = time.perf_counter()
            assert base.data is not None and any(o.name == f"Bench {i}" for o in base.data.objects)
            verdicts.append(t1 - t0)
            reloads.append(t2 - t0)
        return downloads, verdicts, reloads
    finally:
        await client.disconnect()


def _window_redrawn(port: int) -> float | None:
    """The real window's Apply → redrawn, median (None without Xvfb)."""
    if shutil.which("Xvfb") is None:
        print("# mapedit: no Xvfb: the window's Apply → redrawn skipped", file=sys.stderr)
        return None
    xvfb, display = start_xvfb()
    try:
        env = as_installed(dict(os.environ))
        env.update(DISPLAY=display, GSK_RENDERER="cairo", NO_AT_BRIDGE="1", GDK_BACKEND="x11")
        with tempfile.TemporaryDirectory(prefix="rtmu-bench-mapedit-config-") as config:
            env["XDG_CONFIG_HOME"] = config
            out = subprocess.run(
                [sys.executable, "-m", "bench.mapedit_window", str(port), str(REPEAT)],
                env=env,
                capture_output=True,
                text=True,
                timeout=600,
                check=True,
            ).stdout
        return float(json.loads(out.strip().splitlines()[-1])["redrawn_s"])
    finally:
        end_process(xvfb)


def run() -> list[Result]:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "building-1m.map"
        write_map(generate_map(1_000_000, 5_000, seed=3), path)
        with SimThread(SimConfig(port=0, map_path=path, camera=False)) as sim:
            downloads, verdicts, reloads = asyncio.run(_measure(sim.port))
            redrawn = _window_redrawn(sim.port)
    baseline = statistics.median(downloads)
    reloaded = statistics.median(reloads)
    out = [
        Result("mapedit.apply_to_reloaded_s.million", reloaded, "s", baseline=baseline),
        Result("mapedit.apply_to_verdict_s.million", statistics.median(verdicts), "s", baseline=baseline),
    ]
    if redrawn is not None:
        out.append(Result("mapedit.window_apply_to_redrawn_s.million", redrawn, "s", baseline=reloaded))
    return out


if __name__ == "__main__":
    for r in run():
        print(f"{r.name:45s} {r.value:10.3f} {r.unit:3s} baseline={r.baseline}")

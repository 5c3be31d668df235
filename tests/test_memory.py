"""Freed memory goes back to the system after a burst (``rtmu.base.memory``; issue 28: the window's RSS)."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import pytest

import rtmu
from rtmu.ui import tiles
from tile_maps import fitted, random_map_tiles

SRC = Path(rtmu.__file__).resolve().parents[1]

BURST = """
import threading
from rtmu.base.memory import give_back

def rss_kib():
    for line in open("/proc/self/status"):
        if line.startswith("VmRSS:"):
            return int(line.split()[1])

kept = []

def burst():  # 64 MiB in blocks under glibc's mmap threshold, from this thread's heap; one small block
    blocks = [bytearray(100_000) for _ in range(670)]  # made after them stays, so the heap cannot
    kept.append(bytearray(1000))  # simply shrink from its end: what a map decode or a tile burst leaves
    del blocks

worker = threading.Thread(target=burst)
worker.start(); worker.join()
before = rss_kib()
trimmed = give_back()
print(trimmed, before, rss_kib())
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc and glibc's malloc_trim")
def test_a_burst_freed_on_a_helper_thread_leaves_the_process_after_give_back() -> None:
    out = subprocess.run([sys.executable, "-c", BURST], capture_output=True, text=True, timeout=60,
                         env={"PYTHONPATH": str(SRC)})  # fmt: skip
    assert out.returncode == 0, out.stderr
    trimmed, before, after = out.stdout.split()
    assert trimmed == "True"
    assert int(before) - int(after) > 8 * 1024, f"RSS {before} → {after} KiB: the freed heap stayed"


def test_the_tile_worker_gives_memory_back_once_idle_after_a_burst(monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[int] = []
    monkeypatch.setattr(tiles, "give_back", lambda: calls.append(1) or True)
    with random_map_tiles(3) as cache:
        vp = fitted(cache, 800, 480)
        cache.visible(vp.scale, vp.origin, vp.width, vp.height)
        assert cache.wait_idle(10)
        rendered = cache.rendered
        assert rendered > 4
        deadline = time.monotonic() + 10
        while not calls and time.monotonic() < deadline:  # a second after the burst, not during it
            time.sleep(0.01)
        time.sleep(2 * tiles.GIVE_BACK_AFTER_S)
        assert 1 <= len(calls) <= 2, f"{len(calls)} trims for the index and {rendered} tiles: one per burst"

"""Endless maps from a hostile server: how long until the caps stop them, and what they cost in memory.

The server (``tests/client/endless_maps.py``) sends a normal header, then points for ever. With an
honest header (``NumPoints: 2``) the client stops just past the header's own count; with a lying one
(``NumPoints: 100000000``) only the absolute caps stop it (1 M text lines, 5 M binary points).

- ``maps.endless_map_cap_s.<case>``: ``rtmu map`` from start to its exit (code 3), as a process.
- ``maps.endless_map_peak_mb.<case>``: that process's peak resident memory (its own ``VmHWM``);
  baseline: the same command downloading a normal map in this run.
- ``maps.window_endless_map_peak_mb``: the real window (own Xvfb) connected to the lying binary
  server for 15 s, peak resident memory (``VmHWM``); baseline: the window against a normal server.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench.common import Result, end_process, start_xvfb

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))
from client.endless_maps import endless_map_server, run_watching_peak  # noqa: E402
from client.servers import ServerThread, TestServer  # noqa: E402

LYING = 100_000_000
CASES = {
    "text_honest_header": ("text", None),
    "text_lying_header": ("text", LYING),
    "binary_lying_header": ("binary", LYING),
}
WINDOW_SECONDS = 15.0


def _rtmu_map(server: TestServer) -> tuple[float, float, int]:
    """Seconds, peak MB and exit code of one ``rtmu map`` against ``server``."""
    with ServerThread(server) as running, tempfile.TemporaryDirectory() as tmp:
        start = time.monotonic()
        code, peak, _err = run_watching_peak(
            [sys.executable, "-m", "rtmu", "map", f"127.0.0.1:{running.port}", "--out", f"{tmp}/m.map"]
        )
        return time.monotonic() - start, peak, code


def _window_peak_mb(server: TestServer) -> float:
    xvfb, display = start_xvfb()
    env = dict(os.environ, DISPLAY=display, GDK_BACKEND="x11", GSK_RENDERER="cairo", NO_AT_BRIDGE="1")
    env.update(GSETTINGS_BACKEND="memory", XDG_CONFIG_HOME=tempfile.mkdtemp(prefix="rtmu-bench-"))
    try:
        with ServerThread(server) as running:
            app = subprocess.Popen(
                [sys.executable, "-m", "rtmu", "--host", "127.0.0.1", "--port", str(running.port)],
                env=env,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
            try:
                peak = 0.0
                end = time.monotonic() + WINDOW_SECONDS
                while time.monotonic() < end:
                    time.sleep(0.2)
                    with open(f"/proc/{app.pid}/status") as f:
                        for line in f:
                            if line.startswith("VmHWM:"):
                                peak = int(line.split()[1]) / 1024
                return peak
            finally:
                end_process(app)
    finally:
        xvfb.terminate()
        xvfb.wait(5)


def run() -> list[Result]:
    _s, normal_peak, code = _rtmu_map(TestServer())
    if code != 0:
        raise RuntimeError(f"rtmu map of a normal map exited {code}")
    out: list[Result] = []
    for case, (kind, claim) in CASES.items():
        seconds, peak, code = _rtmu_map(endless_map_server(kind, claim))
        if code != 3:
            raise RuntimeError(f"rtmu map against the endless {case} map exited {code}, not 3")
        out.append(Result(f"maps.endless_map_cap_s.{case}", seconds, "s"))
        out.append(Result(f"maps.endless_map_peak_mb.{case}", peak, "MB", baseline=normal_peak))
    window_normal = _window_peak_mb(TestServer())
    window_endless = _window_peak_mb(endless_map_server("binary", LYING))
    out.append(Result("maps.window_endless_map_peak_mb", window_endless, "MB", baseline=window_normal))
    return out


if __name__ == "__main__":
    for r in run():
        print(f"{r.name:45s} {r.value:10.2f} {r.unit:3s} baseline={r.baseline}")

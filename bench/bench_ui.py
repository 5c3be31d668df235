"""The operator window's figures: frame time on a 1 M-point map, launch → first map frame, memory.

* ``ui.frame_ms.1m_follow_100pct.{p50,p95,max}`` (ms): one frame of the map stage
  (``rtmu.ui.frame.draw_frame``, the function the window draws with) into a
  1024×600 cairo surface while the robot drives 40 mm per frame along a corridor
  of a generated 1 M-point building, the view re-centred on it every frame (the
  worst case for follow mode: every frame scrolls). The tile worker renders
  newly exposed tiles at the same time, as in the window. Baseline: the naive
  redraw, every point and segment stroked with cairo each frame (what the
  thesis's client did), median of a few frames in the same run.
* ``ui.frame_ms.1m_fit.p95``: the same with the whole building fitted (~2 %).
* ``ui.frame_speedup.1m_follow_100pct.p50`` and ``ui.frame_speedup.1m_fit.p95`` (x): how many
  times faster than the naive redraw a frame is (naive median ÷ the figure above). The
  ``frame_ms`` figures keep the usual shape, so their ``ratio`` (value ÷ baseline) is a tiny
  number such as 0.0006; these two say the same the way round a reader expects.
* ``ui.launch_to_first_map_frame_s.{office,1m}``: ``rtmu --host … --port …`` started
  as a process until it prints that a frame showed the whole map (simulator in
  another process; best of two launches for the office map).
* ``ui.rss_mb_connected.1m``: the window's resident memory, connected to the
  simulator serving the 1 M-point map, 2 s after that frame. Baseline: the same
  on the office map.

The launch and memory figures need Xvfb (started here if ``DISPLAY`` is unset);
without it they are skipped with a note. Maps go to a temporary directory.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import cairo
import numpy as np

from bench.common import Result, start_xvfb
from rtmu.mapfile import write_map
from rtmu.package_data import project_map
from rtmu.sim.mapgen import generate_map
from rtmu.ui import overlays
from rtmu.ui.frame import Scene, draw_frame
from rtmu.ui.tiles import TileCache
from rtmu.ui.viewport import Viewport, fit_view

POINTS = 1_000_000
LINES = 10_000
SEED = 2024
WIDTH, HEIGHT = 1024, 600
FOLLOW_FRAMES = 400
STEP_MM = 40.0
NAIVE_FRAMES = 3
OFFICE = project_map("office.map")


def naive_frame(ctx: cairo.Context, vp: Viewport, points: np.ndarray, segments: np.ndarray) -> None:
    """Redraw everything with cairo: one path of every segment, a 1 px square per point."""
    ctx.set_source_rgb(0.96, 0.96, 0.95)
    ctx.paint()
    s = vp.scale
    ox, oy = vp.origin
    ctx.set_source_rgb(0.1, 0.1, 0.1)
    ctx.set_line_width(1.5)
    for x0, y0, x1, y1 in segments.tolist():
        ctx.move_to(x0 * s + ox, -y0 * s + oy)
        ctx.line_to(x1 * s + ox, -y1 * s + oy)
    ctx.stroke()
    for x, y in points.tolist():
        ctx.rectangle(x * s + ox, -y * s + oy, 1, 1)
    ctx.fill()


def _ms(values: list[float]) -> tuple[float, float, float]:
    ordered = sorted(values)
    p95 = ordered[min(len(ordered) - 1, math.ceil(0.95 * len(ordered)) - 1)]
    return statistics.median(ordered) * 1e3, p95 * 1e3, ordered[-1] * 1e3


def frame_figures() -> list[Result]:
    data = generate_map(POINTS, LINES, SEED)
    home = data.home()
    assert home is not None
    surface = cairo.ImageSurface(cairo.FORMAT_RGB24, WIDTH, HEIGHT)
    ctx = cairo.Context(surface)
    labels = overlays.LabelCache()
    tiles = TileCache(lambda: None)
    try:
        tiles.set_map(data.points, data.segments)
        if not tiles.wait_idle(60):
            raise RuntimeError("the tile index was not built in time")
        objects = list(data.objects)

        def follow_run(zoom: float) -> tuple[list[float], int]:
            times: list[float] = []
            incomplete = 0
            trail: list[tuple[float, float]] = []
            for k in range(FOLLOW_FRAMES):
                x, y = home.x + k * STEP_MM, home.y
                trail.append((x, y))
                vp = Viewport(WIDTH, HEIGHT, zoom, x, y)
                scene = Scene(labels, tiles, objects, (x, y, 0.0), False, trail[-300:], ())
                t0 = time.perf_counter()
                complete = draw_frame(ctx, vp, scene)
                times.append(time.perf_counter() - t0)
                incomplete += not complete
                time.sleep(1 / 120)  # frames come from the frame clock; the worker gets the gaps
            return times, incomplete

        follow, misses = follow_run(1.0)
        fit = fit_view(tiles.bounds, WIDTH, HEIGHT)  # type: ignore[arg-type]
        fit_times: list[float] = []
        for k in range(60):
            scene = Scene(labels, tiles, objects, (home.x + k * STEP_MM, home.y, 0.0), False, (), ())
            t0 = time.perf_counter()
            draw_frame(ctx, fit, scene)
            fit_times.append(time.perf_counter() - t0)
            if k == 0:
                tiles.wait_idle(30)
        naive_follow: list[float] = []
        for k in range(NAIVE_FRAMES):
            vp = Viewport(WIDTH, HEIGHT, 1.0, home.x + k * STEP_MM, home.y)
            t0 = time.perf_counter()
            naive_frame(ctx, vp, data.points, data.segments)
            naive_follow.append(time.perf_counter() - t0)
        naive_fit: list[float] = []
        for _ in range(NAIVE_FRAMES):
            t0 = time.perf_counter()
            naive_frame(ctx, fit, data.points, data.segments)
            naive_fit.append(time.perf_counter() - t0)
    finally:
        tiles.close()
    print(
        f"# ui: follow at 100 %: {FOLLOW_FRAMES} frames, {misses} drawn from the overview (tiles pending)",
        file=sys.stderr,
    )
    return frame_results(follow, fit_times[1:], naive_follow, naive_fit)


def frame_results(
    follow: list[float], fit: list[float], naive_follow: list[float], naive_fit: list[float]
) -> list[Result]:
    """The frame figures from frame times in seconds (cached frames, then the naive redraws)."""
    p50, p95, worst = _ms(follow)
    fit_p95 = _ms(fit)[1]
    naive = statistics.median(naive_follow) * 1e3
    naive_fit_ms = statistics.median(naive_fit) * 1e3
    return [
        Result("ui.frame_ms.1m_follow_100pct.p50", p50, "ms", naive),
        Result("ui.frame_ms.1m_follow_100pct.p95", p95, "ms", naive),
        Result("ui.frame_ms.1m_follow_100pct.max", worst, "ms", naive),
        Result("ui.frame_ms.1m_fit.p95", fit_p95, "ms", naive_fit_ms),
        Result("ui.frame_speedup.1m_follow_100pct.p50", naive / p50, "x"),
        Result("ui.frame_speedup.1m_fit.p95", naive_fit_ms / fit_p95, "x"),
    ]


# -- whole process: launch to first map frame, resident memory -----------------------------------------


class _Display:
    """``DISPLAY`` if set, else a private Xvfb for as long as the block runs (None when there is none)."""

    def __init__(self) -> None:
        self.proc: subprocess.Popen[bytes] | None = None
        self.display: str | None = os.environ.get("DISPLAY")

    def __enter__(self) -> str | None:
        if self.display or shutil.which("Xvfb") is None:
            return self.display
        try:
            self.proc, self.display = start_xvfb()
        except RuntimeError:
            self.display = None
        return self.display

    def __exit__(self, *exc: object) -> None:
        if self.proc is not None:
            self.proc.terminate()
            with contextlib.suppress(subprocess.TimeoutExpired):
                self.proc.wait(5)


@contextlib.contextmanager
def _simulator(map_path: Path):  # type: ignore[no-untyped-def]
    sim = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "sim", "--port", "0", "--map", str(map_path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    try:
        assert sim.stdout is not None
        line = sim.stdout.readline()
        match = re.search(r"127\.0\.0\.1:(\d+)", line)
        if match is None:
            raise RuntimeError(f"the simulator did not say its port: {line!r}")
        yield int(match.group(1))
    finally:
        _stop(sim)


def _stop(proc: subprocess.Popen) -> None:  # type: ignore[type-arg]
    proc.terminate()
    with contextlib.suppress(subprocess.TimeoutExpired):
        proc.wait(10)
    if proc.poll() is None:
        proc.kill()
        proc.wait(5)


def _rss_mb(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    raise RuntimeError("no VmRSS")


def launch(port: int, display: str, *, settle: float = 2.0, timeout: float = 90.0) -> tuple[float, float]:
    """(seconds to the first complete map frame, RSS in MB ``settle`` s later)."""
    with tempfile.TemporaryDirectory(prefix="rtmu-bench-config-") as config:
        return _launch(port, display, config, settle=settle, timeout=timeout)


def _launch(port: int, display: str, config: str, *, settle: float, timeout: float) -> tuple[float, float]:
    env = dict(os.environ, DISPLAY=display, GSK_RENDERER="cairo", NO_AT_BRIDGE="1", GDK_BACKEND="x11")
    env["XDG_CONFIG_HOME"] = config
    t0 = time.perf_counter()
    proc = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "--host", "127.0.0.1", "--port", str(port), "--report-first-frame"],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        env=env,
    )
    seen = threading.Event()
    elapsed: list[float] = []

    def read() -> None:
        assert proc.stdout is not None
        for line in proc.stdout:
            if "first map frame" in line and not seen.is_set():
                elapsed.append(time.perf_counter() - t0)
                seen.set()

    threading.Thread(target=read, daemon=True).start()
    try:
        if not seen.wait(timeout):
            raise RuntimeError("the window never showed the whole map")
        time.sleep(settle)
        return elapsed[0], _rss_mb(proc.pid)
    finally:
        _stop(proc)


def process_figures() -> list[Result]:
    with _Display() as display:
        if display is None:
            print("# ui: no DISPLAY and no Xvfb: launch and memory figures skipped", file=sys.stderr)
            return []
        with _simulator(OFFICE) as port:
            runs = [launch(port, display) for _ in range(2)]
        office_first = min(r[0] for r in runs)
        office_rss = runs[-1][1]
        with tempfile.TemporaryDirectory(prefix="rtmu-bench-map-") as tmp:
            big = Path(tmp) / "building-1m.map"
            write_map(generate_map(POINTS, LINES, SEED), big)
            with _simulator(big) as port:
                big_first, big_rss = launch(port, display, settle=2.0)
    return [
        Result("ui.launch_to_first_map_frame_s.office", office_first, "s"),
        Result("ui.launch_to_first_map_frame_s.1m", big_first, "s"),
        Result("ui.rss_mb_connected.1m", big_rss, "MB", office_rss),
    ]


def run() -> list[Result]:
    return [*frame_figures(), *process_figures()]

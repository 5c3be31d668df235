"""The operator window at rest and driving: CPU, launch time and memory, against a bare GTK 4 window.

Everything runs as real processes on a private Xvfb: the simulator (office map, camera on, the robot
standing still), the ``rtmu`` window connected to it (``--report-first-frame``), and the baseline,
``bench.bare_window`` (an empty GTK 4 window of the same size). A/B launches alternate; medians.
The bytecode and the compiled dataclass methods (``base.dataclass_code``, in a cache folder of the
run's own) are cached first, as an installed RTMU has them after its first start.

* ``window.launch_to_first_map_frame_s.office`` (s): process start → the first frame showing the
  whole office map. Baseline: the bare window's start → its first frame. Target ≤ 0.6 s.
* ``window.rss_mib_connected.office`` (MiB): the window's resident memory 3 s after that frame
  (the guardian, a process of its own, not counted). Baseline: the bare window's. Target ≤ baseline
  + 50 MiB.
* ``window.idle_cpu_pct`` (% of a core): the window and its children (the guardian) over
  :data:`IDLE_S`, connected to the still robot, map page, nothing touched. Baseline: the bare
  window the same way. Target ≤ 1 %. ``window.idle_cpu_pct.window_only``: the window process alone.
* ``window.follow_drive_cpu_pct`` (% of a core): the same, zoomed in (Follow on, as by default)
  while a drive key is held (``Left``, through X: xdotool) for :data:`DRIVE_S`. Baseline: the
  window idle. Target ≤ 5 %.

Needs Xvfb and xdotool; without them the figures are skipped with a note.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from pathlib import Path

from bench.common import Result, as_installed, cache_bytecode, cpu_seconds, end_process, start_xvfb
from rtmu.package_data import project_map

LAUNCHES = 3
SETTLE_S = 3.0
IDLE_S = 10.0
DRIVE_S = 10.0
REPO = Path(__file__).resolve().parents[1]


def _env(display: str, config: str, cache: str) -> dict[str, str]:
    env = as_installed(dict(os.environ))
    env["XDG_CACHE_HOME"] = cache
    env.update(DISPLAY=display, GSK_RENDERER="cairo", NO_AT_BRIDGE="1", GDK_BACKEND="x11")
    env.update(XDG_CONFIG_HOME=config, GSETTINGS_BACKEND="memory")
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(REPO / "src"), str(REPO), env.get("PYTHONPATH")) if p)
    env.pop("WAYLAND_DISPLAY", None)
    return env


@contextlib.contextmanager
def simulator() -> Iterator[int]:
    sim = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "sim", "--port", "0", "--map", str(project_map("office.map"))],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        env=dict(os.environ, PYTHONPATH=str(REPO / "src")),
    )
    try:
        assert sim.stdout is not None
        line = sim.stdout.readline()
        found = re.search(r"127\.0\.0\.1:(\d+)", line)
        if found is None:
            raise RuntimeError(f"the simulator did not say its port: {line!r}")
        yield int(found.group(1))
    finally:
        end_process(sim)


class Launched:
    """One window process: started, waited for until it printed ``marker``."""

    def __init__(self, argv: list[str], env: dict[str, str], marker: str, timeout: float = 90.0) -> None:
        self.seen = threading.Event()
        started = time.perf_counter()
        self.proc = subprocess.Popen(
            argv, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=env
        )
        self.first_s = 0.0

        def read() -> None:
            assert self.proc.stdout is not None
            for line in self.proc.stdout:
                if marker in line and not self.seen.is_set():
                    self.first_s = time.perf_counter() - started
                    self.seen.set()

        threading.Thread(target=read, daemon=True).start()
        if not self.seen.wait(timeout):
            end_process(self.proc)
            raise RuntimeError(f"{argv[1:4]} never printed {marker!r}")

    def rss_mib(self) -> float:
        for line in Path(f"/proc/{self.proc.pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
        raise RuntimeError("no VmRSS")

    def cpu_pct(self, seconds: float, *, descendants: bool = True) -> tuple[float, float]:
        """(% of a core of the process and its children, % of the process alone) over ``seconds``."""
        pid = self.proc.pid
        all0, own0, t0 = cpu_seconds(pid), cpu_seconds(pid, descendants=False), time.monotonic()
        time.sleep(seconds)
        all1, own1, t1 = cpu_seconds(pid), cpu_seconds(pid, descendants=False), time.monotonic()
        return 100 * (all1 - all0) / (t1 - t0), 100 * (own1 - own0) / (t1 - t0)

    def close(self) -> None:
        end_process(self.proc)


def _xdotool(env: dict[str, str], *args: str) -> str:
    done = subprocess.run(["xdotool", *args], env=env, capture_output=True, text=True, timeout=30, check=True)
    return done.stdout


def warm_dataclass_cache(env: dict[str, str]) -> None:
    """What the window's first start leaves in the user's cache (``base.dataclass_code``)."""
    code = "from rtmu.base import dataclass_code\ndataclass_code.install()\nimport rtmu.ui.application\n"
    subprocess.run([sys.executable, "-c", code], env=env, check=True, capture_output=True, timeout=120)


def measure(display: str, port: int, cache: str) -> dict[str, list[float]]:
    figures: dict[str, list[float]] = {}

    def add(name: str, value: float) -> None:
        figures.setdefault(name, []).append(value)

    rtmu = [sys.executable, "-m", "rtmu", "--host", "127.0.0.1", "--port", str(port), "--report-first-frame"]
    bare = [sys.executable, "-m", "bench.bare_window"]
    for run in range(LAUNCHES):
        with tempfile.TemporaryDirectory(prefix="rtmu-bench-window-") as config:
            env = _env(display, config, cache)
            if run == 0:
                warm_dataclass_cache(env)
            base = Launched(bare, env, "first frame")
            try:
                add("bare_first_s", base.first_s)
                time.sleep(SETTLE_S)
                add("bare_rss", base.rss_mib())
                add("bare_idle", base.cpu_pct(IDLE_S / 2)[0])
            finally:
                base.close()
            window = Launched(rtmu, env, "first map frame")
            try:
                add("first_s", window.first_s)
                time.sleep(SETTLE_S)
                add("rss", window.rss_mib())
                total, own = window.cpu_pct(IDLE_S)
                add("idle", total)
                add("idle_own", own)
                if run == 0:
                    add("drive", drive(window, env))
            finally:
                window.close()
    return figures


def drive(window: Launched, env: dict[str, str]) -> float:
    """% of a core while ``Left`` is held, zoomed in with Follow on (the window and the guardian)."""
    pid = str(window.proc.pid)
    wid = _xdotool(env, "search", "--sync", "--onlyvisible", "--pid", pid, "--name", "RTMU").split()[0]
    _xdotool(env, "windowfocus", "--sync", wid)
    for _ in range(3):
        _xdotool(env, "key", "ctrl+plus")
    time.sleep(1.0)
    _xdotool(env, "keydown", "Left")
    try:
        time.sleep(1.0)  # the drive is under way (lease granted, guardian armed)
        return window.cpu_pct(DRIVE_S)[0]
    finally:
        _xdotool(env, "keyup", "Left")


def run() -> list[Result]:
    if shutil.which("Xvfb") is None or shutil.which("xdotool") is None:
        print("# window: Xvfb and xdotool are needed: figures skipped", file=sys.stderr)
        return []
    cache_bytecode()
    xvfb, display = start_xvfb()
    try:
        with simulator() as port, tempfile.TemporaryDirectory(prefix="rtmu-bench-cache-") as cache:
            f = measure(display, port, cache)
    finally:
        end_process(xvfb)
    m = {k: statistics.median(v) for k, v in f.items()}
    idle = ", ".join(f"{v:.2f}" for v in f["idle"])
    print(f"# window: idle {idle} % of a core; launches {', '.join(f'{v:.2f}' for v in f['first_s'])} s",
          file=sys.stderr)  # fmt: skip
    return [
        Result("window.launch_to_first_map_frame_s.office", m["first_s"], "s", m["bare_first_s"]),
        Result("window.rss_mib_connected.office", m["rss"], "MiB", m["bare_rss"]),
        Result("window.idle_cpu_pct", m["idle"], "% of a core", m["bare_idle"]),
        Result("window.idle_cpu_pct.window_only", m["idle_own"], "% of a core", m["bare_idle"]),
        Result("window.follow_drive_cpu_pct", m["drive"], "% of a core", m["idle"]),
    ]

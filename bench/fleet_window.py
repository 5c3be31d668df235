"""The measured window of ``bench_fleet``: the real application on a fleet profile, in its own process.

``python -m bench.fleet_window SECONDS PORT…`` opens the window on one robot per port (the fleet
path, also for one robot), waits until every robot has a status and a map, measures for
SECONDS, prints one JSON line and quits (stopping every robot). Measured:

* ``frame_ms``: the map stage's own draw time per frame (``MapStage.frame_times``: the other
  robots, their trails and the selected one included), p50/p95/max;
* ``updates_per_s``: per robot, frames that showed a status of it not shown before
  (``FleetBinding.drawn_updates``) per second;
* ``cpu``: CPU seconds per second of this process and its children (the guardian processes)
  over the same interval, from ``/proc``; ``cpu_window``: this process alone;
* ``map_downloads``: sessions that downloaded the map themselves (the others took another's).
"""

from __future__ import annotations

import json
import os
import statistics
import sys
import tempfile
import time
from collections import deque
from pathlib import Path

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import GLib  # noqa: E402

from rtmu.settings.store import DirectRobot  # noqa: E402
from rtmu.ui.application import RtmuApplication  # noqa: E402
from rtmu.ui.options import GuiOptions  # noqa: E402

TICKS = os.sysconf("SC_CLK_TCK")


def cpu_seconds(pid: int, *, descendants: bool = True) -> float:
    """utime + stime of ``pid`` and (unless told not to) every live descendant."""
    children: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        children.setdefault(int(fields[1]), []).append(int(entry.name))
    total, todo = 0.0, [pid]
    while todo:
        p = todo.pop()
        try:
            fields = Path(f"/proc/{p}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        total += (int(fields[11]) + int(fields[12])) / TICKS
        todo += children.get(p, []) if descendants else []
    return total


def describe() -> str:
    """Each robot's connection phase, map state and whether it has a status (why it is not ready)."""
    app = RtmuApplication.get_default()
    fleet = getattr(app, "fleet", None)
    if fleet is None:
        return "no application"
    return "; ".join(
        f"{s.name}: {s.state.connection.value.phase.value}, map {s.state.map.value.state}, "
        f"status {'yes' if s.state.robot.value.numbers_at is not None else 'no'}"
        for s in fleet
    )


def pump_until(ready, timeout: float) -> None:  # type: ignore[no-untyped-def]
    ctx = GLib.MainContext.default()
    deadline = time.monotonic() + timeout
    while not ready():
        if time.monotonic() > deadline:
            raise SystemExit(f"the fleet never became ready: {describe()}")
        ctx.iteration(True)


def main(seconds: float, ports: list[int]) -> None:
    started = time.monotonic()
    robots = tuple(DirectRobot(f"robot{i + 1}", "127.0.0.1", p) for i, p in enumerate(ports))
    config = Path(tempfile.mkdtemp(prefix="rtmu-bench-fleet-")) / "settings.toml"
    app = RtmuApplication(GuiOptions(fleet=robots, settings_path=config, persist=False))
    app.register(None)
    app.activate()
    fleet = app.fleet

    def ready() -> bool:
        return len(fleet) == len(ports) and all(
            s.state.robot.value.numbers_at is not None and s.state.map.value.state == "ready" for s in fleet
        )

    pump_until(ready, 600)
    waited = time.monotonic()
    window, binding = app.window, app.fleet_binding
    assert window is not None and binding is not None
    pump_until(lambda: window.stage.last_frame_complete, 60)
    end = time.monotonic() + 2.0  # settle: tiles rendered, first layout done
    pump_until(lambda: time.monotonic() > end, 10)
    window.stage.frame_times = deque(maxlen=1_000_000)  # every frame of the interval, not the last 240
    before = dict(binding.drawn_updates)
    own0 = cpu_seconds(os.getpid(), descendants=False)
    cpu0, t0 = cpu_seconds(os.getpid()), time.monotonic()
    end = t0 + seconds
    pump_until(lambda: time.monotonic() > end, seconds + 10)
    cpu1, t1 = cpu_seconds(os.getpid()), time.monotonic()
    own1 = cpu_seconds(os.getpid(), descendants=False)
    frames = sorted(window.stage.frame_times)
    rates = {name: (binding.drawn_updates.get(name, 0) - before.get(name, 0)) / (t1 - t0) for name in
             (s.name for s in fleet)}  # fmt: skip
    out = {
        "robots": len(ports),
        "frames": len(frames),
        "frame_ms_p50": statistics.median(frames) * 1e3,
        "frame_ms_p95": frames[min(len(frames) - 1, int(0.95 * len(frames)))] * 1e3,
        "frame_ms_max": frames[-1] * 1e3,
        "updates_per_s_min": min(rates.values()),
        "updates_per_s_mean": statistics.fmean(rates.values()),
        "cpu": (cpu1 - cpu0) / (t1 - t0),
        "ready_s": waited - started,
        "cpu_window": (own1 - own0) / (t1 - t0),
        "map_downloads": sum(
            1 for s in fleet if s.runner.session is not None and s.runner.session.maps.downloads_shared == 0
        ),
    }
    print("RESULT " + json.dumps(out), flush=True)
    app.close_session()


if __name__ == "__main__":
    args = (float(sys.argv[1]), [int(p) for p in sys.argv[2:]])
    profile = os.environ.get("RTMU_BENCH_PROFILE")  # a path: cProfile the window into it (finding costs)
    if profile:
        import cProfile

        cProfile.run("main(*args)", profile)
    else:
        main(*args)

"""Real Wi-Fi and a busy laptop: false stops, stop latencies under real faults, what the keeper costs.

Every figure is measured twice in the same run: with the limits RTMU learns per link
(``base.link_timing``, the lease keeper) and, as the baseline, with the fixed thresholds it had
before (``RTMU_LINK_TIMING=fixed``: stale after 3 status intervals in the window, 200 ms for
``rtmu drive``, pings 2 s / 0.5 s, the guardian's 0.4 s, no run-queue credit).

* ``links.false_stops_per_10min.{window,core,drive}.{good,busy,load4}`` — a held drive for
  ``RTMU_LINKS_SOAK_S`` s (baseline ``RTMU_LINKS_BASELINE_S``) through the fault proxy playing the
  issue's "good" / "busy" Wi-Fi, or on a clean link under 4 spinning processes (nice 0) on this
  2-core machine; every stop is a false one, scaled to 10 minutes. ``window`` is the real app under
  Xvfb, a key held with xdotool (``bench.links_window``); ``core`` the window's client core (runner,
  lease, keeper, guardian) with its UI thread played by a thread that does 8 ms of GIL-free work per
  40 ms frame (``bench.links_parent``); ``drive`` is ``rtmu drive``. The three run at once, one
  condition after the other, each with its simulator and proxy in a process of its own
  (``bench.links_rig_proc``: shared, their interpreter lock would add its own delays to the link's)
  and, where allowed, a few nice levels up: it stands for the robot, whose CPUs the laptop's load
  does not take.
* ``links.stop_sent_ms.<fault>`` — from the last server bytes the client received to zero ratios +
  ``stop`` leaving the client (its own report, same monotonic clock); ``links.stop_at_sim_ms.<fault>``
  — to their arrival at the simulator, where the fault lets them through; ``reset`` is timed from
  the fault. p50/p95/max over ``RTMU_LINKS_TRIALS`` (20) trials per fault, the core client.
* ``links.release_during_freeze_mm.{frozen,starved}`` — how far the robot drives after the operator
  lets go 0.2 s into a 0.8 s UI freeze: ``frozen`` the UI thread busy with its own work, ``starved``
  it only waits for a CPU (pinned to one core at nice 15 behind six spinners: ~2 % of the core).
  The keeper's cost is the ``starved`` row (value vs baseline); ``links.false_stops.starved_hold``
  counts the 0.8 s starvations that stopped a drive the operator kept holding
  (``RTMU_LINKS_FREEZE_TRIALS``, 10).

``RTMU_LINKS_CONDITIONS=load4`` (comma-separated) soaks only those conditions and
``RTMU_LINKS_BASELINE_S=0`` skips the baseline, while diagnosing one of them.
``RTMU_LINKS_TRACE=DIR`` keeps every simulator's clocks and a machine-wide stall probe for the
false-stop soaks; ``python -m bench.links_trace DIR`` then names the late clock of each stop.

Run alone: ``python -m bench.bench_links``.
"""

from __future__ import annotations

import contextlib
import math
import os
import signal
import statistics
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

from bench.common import Result
from bench.links_rig import REPO, CoreParent, Rig, RigProcess, drive
from bench.links_window import window_false_stops as window_false_stops_in
from rtmu.base.exit_codes import EXIT_TIMEOUT

sys.path.insert(0, str(REPO / "tests"))
from cpuload import CpuLoad, wait_busy
from linkfaults import BUSY_WIFI, GOOD_WIFI, TO_CLIENT, TO_SERVER, FaultProxy

SOAK_S = float(os.environ.get("RTMU_LINKS_SOAK_S", "60"))
BASELINE_S = float(os.environ.get("RTMU_LINKS_BASELINE_S", str(min(SOAK_S, 120.0))))
TRIALS = int(os.environ.get("RTMU_LINKS_TRIALS", "20"))
FREEZE_TRIALS = int(os.environ.get("RTMU_LINKS_FREEZE_TRIALS", "10"))
PROFILES = {"good": GOOD_WIFI, "busy": BUSY_WIFI}
CONDITIONS = os.environ.get("RTMU_LINKS_CONDITIONS", "good,busy,load4").split(",")
"""The false-stop soak's conditions (all three by default; one alone while diagnosing it)."""
SAME_STOP = 0.5
"""Stops (and guardian reports) closer than this are one event."""

FAULTS: dict[str, tuple[Callable[[FaultProxy], float], bool]] = {
    # name: (apply, can the stop reach the simulator before the fault is undone)
    "mute_to_client": (lambda p: p.mute(TO_CLIENT), True),
    "stalling_header": (lambda p: p.stalling_header(), True),
    "garbage": (lambda p: p.garble(TO_CLIENT), True),
    "partition": (lambda p: p.mute(TO_CLIENT, TO_SERVER), False),
    "roam": (lambda p: p.roam(1.5), False),
    "reset": (lambda p: p.reset(), True),
}


def _events(times: list[float]) -> int:
    count, last = 0, -math.inf
    for t in sorted(times):
        if t - last > SAME_STOP:
            count += 1
        last = t
    return count


def core_false_stops(condition: str, seconds: float, fixed: bool, seed: int) -> tuple[int, float]:
    """(false stops, seconds held) for the core client under ``condition``."""
    rig = RigProcess(seed)
    try:
        if condition in PROFILES:
            rig.play(condition, seed)
        parent = CoreParent(rig.port, fixed=fixed)
        try:
            if not rig.wait(rig.moving, 20):
                raise RuntimeError("the core client never drove")
            start = time.monotonic()
            handled = 0
            while time.monotonic() - start < seconds:
                stops = [t for t, _ in parent.stops + parent.guardian if t >= start]
                if len(stops) > handled:
                    handled = len(stops)
                    time.sleep(0.3)
                    parent.send("press")  # the operator presses again
                time.sleep(0.05)
            held = time.monotonic() - start
            said = [(t, why) for t, why in parent.stops + parent.guardian if start <= t <= start + held]
            for t, why in said:
                logged = " | ".join(text for at, text in parent.logs if abs(at - t) < 0.3)
                print(
                    f"# links core/{condition} fixed={fixed}: stop at {t - start:.1f} s: {why} [{logged}]",
                    flush=True,
                )
            return _events([t for t, _ in said]), held
        finally:
            parent.close()
    finally:
        rig.close()


def drive_false_stops(condition: str, seconds: float, fixed: bool, seed: int) -> tuple[int, float]:
    """(false stops, seconds driven) for ``rtmu drive``: a stopped drive starts again."""
    rig = RigProcess(seed)
    try:
        if condition in PROFILES:
            rig.play(condition, seed)
        stops, driven = 0, 0.0
        while driven < seconds - 1.0:
            before = rig.drives()
            code, err = drive(rig.port, seconds - driven, fixed=fixed)
            driven += (rig.drives() - before) * 0.1  # sent every 100 ms while driving
            load = os.getloadavg()[0]
            if code == EXIT_TIMEOUT:  # a link fault (rtmu drive's LinkFault): every one is false here
                stops += 1
                said = f"{err.strip()[:300]} (load {load:.1f})"
                print(f"# links drive/{condition} fixed={fixed}: {said}", flush=True)
            elif code != 0:  # not the link's: a wall reached after minutes of driving ahead, say
                rig.reset_pose()
                print(f"# links drive/{condition} fixed={fixed}: not a link stop, not counted (exit {code}): "
                      f"{err.strip()[:200]}", flush=True)  # fmt: skip
        return stops, driven
    finally:
        rig.close()


def window_false_stops(condition: str, seconds: float, fixed: bool, seed: int) -> tuple[int, float]:
    """(false stops, seconds held) for the real window (``bench.links_window``)."""
    rig = RigProcess(seed)
    try:
        if condition in PROFILES:
            rig.play(condition, seed)
        count, held, who = window_false_stops_in(rig, seconds, fixed)
        for stop in who:
            print(f"# links window/{condition} fixed={fixed}: stop by {stop}", flush=True)
        return count, held
    finally:
        rig.close()


def _per_10min(count: int, seconds: float) -> float:
    return count * 600.0 / max(seconds, 1.0)


def false_stop_rows() -> list[Result]:
    """Wi-Fi phase (4 runs at once), then load phase (2 at once under 4 spinners); learned, then fixed."""
    figures: dict[tuple[str, str, bool], float] = {}

    def phase(conditions: tuple[str, ...], seconds: float, fixed: bool) -> None:
        jobs: list[threading.Thread] = []
        for i, condition in enumerate(conditions, start=1):
            for who, fn in (
                ("core", core_false_stops),
                ("drive", drive_false_stops),
                ("window", window_false_stops),
            ):

                def job(who: str = who, fn: Any = fn, condition: str = condition, seed: int = i) -> None:
                    count, held = fn(condition, seconds, fixed, seed)
                    figures[(who, condition, fixed)] = _per_10min(count, held)
                    print(f"# links {who}/{condition} fixed={fixed}: {count} stops in {held:.0f} s")

                jobs.append(threading.Thread(target=job, daemon=True))
        for j in jobs:
            j.start()
        for j in jobs:
            j.join()

    trace = os.environ.get("RTMU_LINKS_TRACE")  # each rig writes its clocks there (``bench.links_trace``)
    probe = None
    if trace:
        total = 3 * (SOAK_S + BASELINE_S) + 600
        argv = [sys.executable, "-m", "bench.stall_probe", f"{trace}/probe.json", str(total)]
        probe = subprocess.Popen(argv, cwd=REPO)
    for fixed, seconds in ((False, SOAK_S), (True, BASELINE_S)):
        if seconds <= 0:
            continue  # (RTMU_LINKS_BASELINE_S=0: no baseline, while diagnosing)
        for profile in ("good", "busy"):
            if profile in CONDITIONS:
                phase((profile,), seconds, fixed)
        if "load4" in CONDITIONS:
            with CpuLoad(count=4, nice=0, seconds=seconds + 300) as load:
                wait_busy(load)
                phase(("load4",), seconds, fixed)
    if probe is not None:
        probe.terminate()
    out = []
    for who in ("window", "core", "drive"):
        for condition in ("good", "busy", "load4"):
            learned = figures.get((who, condition, False))
            if learned is not None:
                name = f"links.false_stops_per_10min.{who}.{condition}"
                out.append(Result(name, learned, "count", figures.get((who, condition, True))))
    out.append(Result("links.false_stop_soak_seconds", SOAK_S, "s", BASELINE_S))
    return out


def _press_until_driving(rig: Rig, parent: CoreParent, timeout: float = 20.0) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        parent.send("press")
        if rig.wait(rig.moving, 1.0):
            return True
    return False


def latency_trials(fault: str, fixed: bool, trials: int) -> dict[str, list[float]]:
    """Per trial: ms from the last bytes received to the stop sent, and to its arrival."""
    apply, reaches = FAULTS[fault]
    out: dict[str, list[float]] = {"sent": [], "at_sim": []}
    rig = Rig(seed=7)
    try:
        parent = CoreParent(rig.proxy.port, fixed=fixed)
        try:
            for _ in range(trials):
                if not _press_until_driving(rig, parent):
                    break
                time.sleep(1.0)
                at = apply(rig.proxy)
                last = rig.proxy.delivered_at[TO_CLIENT] or at
                sent = parent.stop_after(at, 5.0)
                arrived = rig.stop_after(at, 5.0) if reaches else None
                if sent is not None and fault != "reset":
                    out["sent"].append((sent[0] - last) * 1000.0)
                if arrived is not None:
                    out["at_sim"].append((arrived - (at if fault == "reset" else last)) * 1000.0)
                time.sleep(0.3)
                rig.proxy.restore()
                rig.wait(lambda: not rig.moving(), 5.0)
        finally:
            parent.close()
    finally:
        rig.close()
    return out


def _stats(name: str, values: list[float], baseline: list[float]) -> list[Result]:
    if not values:
        return []

    def q(v: list[float], p: float) -> float | None:
        if not v:
            return None
        v = sorted(v)
        return v[min(len(v) - 1, round(p * (len(v) - 1)))]

    return [
        Result(f"{name}.p50", q(values, 0.5) or 0.0, "ms", q(baseline, 0.5)),
        Result(f"{name}.p95", q(values, 0.95) or 0.0, "ms", q(baseline, 0.95)),
        Result(f"{name}.max", max(values), "ms", max(baseline, default=None)),
    ]


def latency_rows() -> list[Result]:
    out: list[Result] = []
    for fault in FAULTS:
        learned = latency_trials(fault, False, TRIALS)
        fixed = latency_trials(fault, True, TRIALS)
        print(f"# links latency {fault}: learned {learned} fixed {fixed}", flush=True)
        if fault != "reset":
            out += _stats(f"links.stop_sent_ms.{fault}", learned["sent"], fixed["sent"])
        out += _stats(f"links.stop_at_sim_ms.{fault}", learned["at_sim"], fixed["at_sim"])
    return out


class Starver:
    """Six spinners pinned to one CPU, paused until :meth:`starve` lets them run for a while."""

    def __init__(self, cpu: int) -> None:
        self.cpu = cpu
        self.load = CpuLoad(count=6, nice=0, seconds=1800, cpus=(cpu,)).start()
        wait_busy(self.load)
        self._signal(signal.SIGSTOP)

    def _signal(self, signum: int) -> None:
        for p in self.load.procs:
            with contextlib.suppress(ProcessLookupError):
                os.kill(p.pid, signum)

    def starve(self, tid: int, seconds: float) -> None:
        """Thread ``tid`` gets ~2 % of its core for ``seconds`` (nice 15 behind six nice-0 spinners)."""
        os.sched_setaffinity(tid, {self.cpu})
        os.setpriority(os.PRIO_PROCESS, tid, 15)
        self._signal(signal.SIGCONT)

        def end() -> None:
            self._signal(signal.SIGSTOP)
            with contextlib.suppress(OSError):  # lowering it back needs the rights a bench has as root
                os.setpriority(os.PRIO_PROCESS, tid, 0)

        threading.Timer(seconds, end).start()

    def close(self) -> None:
        self._signal(signal.SIGCONT)
        self.load.stop()


def freeze_trials(kind: str, fixed: bool, trials: int, release: bool) -> list[float]:
    """mm driven after a release 0.2 s into a 0.8 s freeze (``release``), or stops without one."""
    rig = Rig(seed=3)
    starver = Starver(sorted(os.sched_getaffinity(0))[0]) if kind == "starved" else None
    out: list[float] = []
    try:
        parent = CoreParent(rig.proxy.port, fixed=fixed)
        try:
            for _ in range(trials):
                rig.sim.call(rig.sim.server.reset_pose)
                if not _press_until_driving(rig, parent):
                    break
                time.sleep(1.0)
                t0 = time.monotonic()
                stops_before = len(parent.stops) + len(parent.guardian)
                if starver is not None:
                    starver.starve(parent.ui_tid, 0.8)
                else:
                    parent.send("freeze", 0.8)
                if not release:
                    time.sleep(1.3)
                    stopped = len(parent.stops) + len(parent.guardian) > stops_before
                    out.append(1.0 if stopped else 0.0)
                    parent.send("release", time.monotonic())
                    rig.wait(lambda: not rig.moving(), 5.0)
                    continue
                release_at = t0 + 0.2
                parent.send("release", f"{release_at:.6f}")
                time.sleep(max(0.0, release_at - time.monotonic()))
                a = rig.sim.snapshot()
                rig.wait(lambda: not rig.moving() and abs(rig.sim.snapshot().vel) < 1.0, 5.0)
                b = rig.sim.snapshot()
                out.append(math.hypot(b.x - a.x, b.y - a.y))
                time.sleep(0.7)  # the freeze is over
        finally:
            parent.close()
    finally:
        if starver is not None:
            starver.close()
        rig.close()
    return out


def freeze_rows() -> list[Result]:
    out: list[Result] = []
    for kind in ("frozen", "starved"):
        after = freeze_trials(kind, False, FREEZE_TRIALS, True)
        before = freeze_trials(kind, True, FREEZE_TRIALS, True)
        print(f"# links release during {kind}: after {after} before {before}", flush=True)
        if after:
            out.append(
                Result(
                    f"links.release_during_freeze_mm.{kind}",
                    statistics.median(after),
                    "mm",
                    statistics.median(before) if before else None,
                )
            )
            worst = max(before, default=None)
            out.append(Result(f"links.release_during_freeze_mm.{kind}.max", max(after), "mm", worst))
    held = freeze_trials("starved", False, FREEZE_TRIALS, False)
    held_fixed = freeze_trials("starved", True, FREEZE_TRIALS, False)
    out.append(Result("links.false_stops.starved_hold", sum(held), "count", sum(held_fixed)))
    out.append(Result("links.freeze_trials", float(FREEZE_TRIALS), "count"))
    return out


def run() -> list[Result]:
    """``RTMU_LINKS_PARTS`` (``freeze,latency,false`` by default) picks the parts to measure."""
    parts = {"freeze": freeze_rows, "latency": latency_rows, "false": false_stop_rows}
    chosen = os.environ.get("RTMU_LINKS_PARTS", ",".join(parts)).split(",")
    return [r for name in chosen if name in parts for r in parts[name]()]


if __name__ == "__main__":
    parts = {"freeze": freeze_rows, "latency": latency_rows, "false": false_stop_rows}
    chosen = [parts[a] for a in sys.argv[1:] if a in parts] or [run]
    for part in chosen:
        for r in part():
            print(f"{r.name:55s} {r.value:10.1f} {r.unit:6s} baseline={r.baseline}")

"""How fast the robot stops when the driving process is frozen (SIGSTOP) or killed (SIGKILL).

Each trial starts a driving process (``bench.safety_parent``: the window's client
core — fleet, runner, lease, its one shared guardian — without GTK), waits until the
simulator drives, sends the signal, and times until the simulator stops commanding
motion: a ``stop`` arrives (the guardian's) or its own 2 s ratio-drive watchdog fires.
``safety.stop_after_window_*`` are the window's shared guardian; ``safety.own_guardian_*``
the guardian of its own that ``rtmu bridge --allow-drive`` starts (``rtmu drive``'s works
the same way). The baseline is the same with the guardian disabled (the watchdog alone),
measured in the same run. A soak drives with a healthy process and counts the guardian's
stops (each one would be a false alarm: a ``stop`` resets an ARIA server's mode).

``RTMU_BENCH_SAFETY_TRIALS`` (default 20) and ``RTMU_BENCH_SAFETY_SOAK_S`` (default
60; 600 for the 10-minute soak) size it. Run alone: ``python -m bench.bench_safety``.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from rtmu.guardian.halt import IDENTIFIER
from rtmu.sim import SimConfig, SimThread

from .common import Result

REPO = Path(__file__).resolve().parents[1]
TRIALS = int(os.environ.get("RTMU_BENCH_SAFETY_TRIALS", "20"))
SOAK_S = float(os.environ.get("RTMU_BENCH_SAFETY_SOAK_S", "60"))


def _parent(sim: SimThread, guardian: str, soak: float | None = None) -> subprocess.Popen[str]:
    argv = [sys.executable, "-m", "bench.safety_parent", str(sim.port), guardian]
    if soak is not None:
        argv.append(str(soak))
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, text=True, cwd=REPO)
    assert proc.stdout is not None
    if proc.stdout.readline().strip() != "driving":
        proc.kill()
        raise RuntimeError("the driving process did not start")
    return proc


def _wait(condition, timeout: float) -> bool:  # type: ignore[no-untyped-def]
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.001)
    return True


def trial(sim: SimThread, signum: int, guardian: str) -> float:
    """Milliseconds from the signal until the simulator stopped commanding motion."""
    server = sim.server
    proc = _parent(sim, guardian)
    try:
        if not _wait(lambda: abs(sim.snapshot().vel) > 1.0, 10):
            raise RuntimeError("the robot never drove")
        time.sleep(0.3)
        stops, watchdog = len(server.stop_log), server.world.ratio_mode.timeouts
        t0 = time.monotonic()
        os.kill(proc.pid, signum)
        # Plain reads of a deque's length and an int from the sim's thread: no round trip per poll.
        if not _wait(lambda: len(server.stop_log) > stops or server.world.ratio_mode.timeouts > watchdog, 5):
            raise RuntimeError("nothing stopped the robot within 5 s")
        return (time.monotonic() - t0) * 1000.0
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGCONT)
            proc.kill()
        proc.wait(5)
        _wait(lambda: not server.sessions, 5)  # the guardian has gone too
        sim.call(server.reset_pose)


def soak(sim: SimThread, seconds: float) -> tuple[int, int]:
    """(stops sent by the guardian, mode changes) while a healthy process drives for ``seconds``."""
    server = sim.server
    before = len(server.stop_log)
    proc = _parent(sim, "shared", seconds)
    changes = 0
    try:
        _wait(lambda: server.world.mode.NAME == "ratioDrive", 10)
        mode = server.world.mode.NAME
        end = time.monotonic() + seconds - 0.5
        while time.monotonic() < end:
            now = server.world.mode.NAME
            if now != mode:
                changes += 1
                mode = now
            time.sleep(0.01)
        assert proc.stdout is not None
        proc.stdout.readline()  # "done": it closed cleanly
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.wait(10)
    stops = list(server.stop_log)[before:] if before < len(server.stop_log) else []
    return sum(1 for _t, _i, who in stops if who == IDENTIFIER), changes


def _stats(name: str, values: list[float], baseline: list[float]) -> list[Result]:
    out = []
    for label, q in (("p50", 50), ("p95", 95), ("max", 100)):
        out.append(
            Result(
                f"{name}.{label}",
                float(np.percentile(values, q)),
                "ms",
                float(np.percentile(baseline, q)) if baseline else None,
            )
        )
    return out


def run() -> list[Result]:
    results: list[Result] = []
    with SimThread(SimConfig(port=0, seed=1, max_clients=10)) as sim:
        for signum, what in ((signal.SIGSTOP, "freeze"), (signal.SIGKILL, "kill")):
            watchdog_only = [trial(sim, signum, "none") for _ in range(max(3, TRIALS))]
            for name, mode in (
                (f"safety.stop_after_window_{what}_ms", "shared"),
                (f"safety.own_guardian_stop_after_{what}_ms", "own"),
            ):
                guarded = [trial(sim, signum, mode) for _ in range(TRIALS)]
                results += _stats(name, guarded, watchdog_only)
        spurious, changes = soak(sim, SOAK_S)
        results.append(Result("safety.guardian_spurious_stops", float(spurious), "count"))
        results.append(Result("safety.soak_mode_changes", float(changes), "count"))
        results.append(Result("safety.soak_seconds", SOAK_S, "s"))
    return results


if __name__ == "__main__":
    for r in run():
        print(f"{r.name:45s} {r.value:10.1f} {r.unit:6s} baseline={r.baseline}")

"""How fast ``rtmu drive`` stops the robot after a link fault, as the simulator sees it.

``rtmu drive`` runs as its own process, through the tests' fault-injecting proxy
(``tests/linkfaults.py``) to the simulator in this process. Each trial: drive, apply one fault,
then poll the simulator every few ms until the robot's commanded velocity is zero; the figure is
that instant minus the moment the proxy applied the fault (``safety.cli_drive_stop_after_fault_ms
.<fault>`` p50/p95/max). The baseline is what a drive that goes blind leaves to the server: the
same drive SIGSTOPped together with its guardian, stopped only by the simulator's 2 s ratioDrive
watchdog, measured in this run.

``safety.cli_drive_false_stops.fake_header`` counts trials in which one injected fake packet
header stopped the drive within 6 s: the decoder resynchronises, so the right answer is 0.

``rtt_800ms`` includes the proxy's own 400 ms on the way to the server (the stop cannot arrive
sooner); ``reset`` leaves nothing to carry a stop, so it measures the server's watchdog too.
``RTMU_LINKFAULT_TRIALS`` sets the trials per fault (default 5).
"""

from __future__ import annotations

import contextlib
import os
import signal
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

from bench.common import Result
from rtmu.package_data import project_map
from rtmu.sim import SimConfig, SimThread

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))
from linkfaults import FAKE_HEADER, TO_CLIENT, FaultProxy  # noqa: E402

ARENA = project_map("arena.map")
POLL = 0.005
GIVE_UP = 6.0

FAULTS: dict[str, Callable[[FaultProxy], float]] = {
    "mute_to_client": lambda p: p.mute(TO_CLIENT),
    "rtt_800ms": lambda p: p.delay(0.4),
    "reset": lambda p: p.reset(),
}
NOISE: dict[str, Callable[[FaultProxy], float]] = {
    # Since the decoder drops a lying header once the stream visibly goes on without it, one fake
    # header no longer stalls status: the drive must go on (a false stop resets the robot's mode).
    "fake_header": lambda p: p.inject(FAKE_HEADER),
}


def _wait(cond: Callable[[], bool], timeout: float) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if cond():
            return True
        time.sleep(POLL)
    return False


def _trial(sim: SimThread, apply: Callable[[FaultProxy], float] | None) -> float | None:
    """ms from the fault (or SIGSTOP of the drive, when ``apply`` is None) to zero commanded velocity."""
    with FaultProxy("127.0.0.1", sim.port) as proxy:
        args = [sys.executable, "-m", "rtmu", "drive", f"127.0.0.1:{proxy.port}", "--trans", "60"]
        proc = subprocess.Popen(
            [*args, "--seconds", "30", "--timeout", "5"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        try:
            if not _wait(lambda: sim.snapshot().trans_ratio == 60, 10):
                return None
            time.sleep(0.3)
            if apply is None:  # freeze the drive and its guardian: only the server's watchdog is left
                for pid in (proc.pid, *_children(proc.pid)):
                    os.kill(pid, signal.SIGSTOP)
                at = time.monotonic()
            else:
                at = apply(proxy)
            if not _wait(lambda: sim.snapshot().trans_ratio == 0, GIVE_UP):
                return None
            return (time.monotonic() - at) * 1000.0
        finally:
            # The guardian too, and SIGCONT first: a SIGSTOPped process never dies of a signal
            # it cannot run, and an orphaned frozen guardian would linger after the bench.
            for pid in (*_children(proc.pid), proc.pid):
                for signum in (signal.SIGCONT, signal.SIGKILL):
                    with contextlib.suppress(ProcessLookupError):
                        os.kill(pid, signum)
            proc.wait()
            _wait(lambda: sim.snapshot().trans_ratio == 0, 3)


def _children(pid: int) -> list[int]:
    """The child processes of ``pid`` (its guardian), from /proc."""
    try:
        text = Path(f"/proc/{pid}/task/{pid}/children").read_text()
    except OSError:
        return []
    return [int(p) for p in text.split()]


def _stats(name: str, values: list[float], baseline: float | None) -> list[Result]:
    if not values:
        return []
    values = sorted(values)
    p95 = values[min(len(values) - 1, round(0.95 * (len(values) - 1)))]
    return [
        Result(f"{name}.p50", statistics.median(values), "ms", baseline),
        Result(f"{name}.p95", p95, "ms", baseline),
        Result(f"{name}.max", values[-1], "ms", baseline),
    ]


def run() -> list[Result]:
    trials = int(os.environ.get("RTMU_LINKFAULT_TRIALS", "5"))
    out: list[Result] = []
    with SimThread(SimConfig(port=0, map_path=ARENA)) as sim:
        blind = [v for v in (_trial(sim, None) for _ in range(2)) if v is not None]
        baseline = statistics.median(blind) if blind else None
        if baseline is not None:
            out.append(Result("safety.cli_drive_stop_after_fault_ms.watchdog_only", baseline, "ms"))
        for fault, apply in FAULTS.items():
            values = [v for v in (_trial(sim, apply) for _ in range(trials)) if v is not None]
            out += _stats(f"safety.cli_drive_stop_after_fault_ms.{fault}", values, baseline)
        for noise, apply in NOISE.items():
            stops = sum(1 for _ in range(trials) if _trial(sim, apply) is not None)
            out.append(Result(f"safety.cli_drive_false_stops.{noise}", stops, "count"))
    return out


if __name__ == "__main__":
    for r in run():
        print(f"{r.name:60s} {r.value:9.1f} {r.unit}  (baseline {r.baseline})")

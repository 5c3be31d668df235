"""A CPU-load generator for tests and benchmarks: N busy processes at a chosen niceness, bounded.

An operator's laptop runs other programs; "4 busy processes on 2 cores" is a load average near 6
before RTMU does anything. :class:`CpuLoad` starts ``count`` processes that spin at ``nice``
(0: as hungry as RTMU itself; 19: polite), optionally pinned to some CPUs, and ends them on
:meth:`stop` / leaving the ``with``.
Each one also ends by itself after ``seconds`` and when its parent goes away (it checks its parent
pid while it spins), so a crashed test or bench never leaves a core burning::

    with CpuLoad(count=4, nice=0, seconds=120):
        ...drive...
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import time

SPIN = """
import os, sys, time
os.setpriority(os.PRIO_PROCESS, 0, int(sys.argv[2]))  # that niceness, whatever the parent's thread had
if sys.argv[3]:
    os.sched_setaffinity(0, {int(c) for c in sys.argv[3].split(",")})
end = time.monotonic() + float(sys.argv[1])
parent = os.getppid()
n = 0
while True:
    n += 1
    if n % 200_000 == 0 and (time.monotonic() > end or os.getppid() != parent):
        break
"""
MAX_SECONDS = 3600.0


class CpuLoad:
    """``count`` spinning processes at ``nice``, each ending after ``seconds`` at the latest."""

    def __init__(
        self, count: int = 4, nice: int = 0, seconds: float = 600.0, cpus: tuple[int, ...] = ()
    ) -> None:
        if not 0 <= nice <= 19:
            raise ValueError("nice must be 0…19 (raising priority needs privileges we do not ask for)")
        if not 0 < seconds <= MAX_SECONDS:
            raise ValueError(f"seconds must be in (0, {MAX_SECONDS:g}]: the load is always bounded")
        self.count = count
        self.nice = nice
        self.seconds = seconds
        self.cpus = cpus
        """Pin the spinners to these CPUs (empty: wherever the kernel puts them)."""
        self.procs: list[subprocess.Popen[bytes]] = []

    def start(self) -> CpuLoad:
        for _ in range(self.count):
            cpus = ",".join(str(c) for c in self.cpus)
            argv = [sys.executable, "-c", SPIN, str(self.seconds), str(self.nice), cpus]
            self.procs.append(subprocess.Popen(argv, stdin=subprocess.DEVNULL))
        return self

    def running(self) -> int:
        return sum(1 for p in self.procs if p.poll() is None)

    def stop(self) -> None:
        for p in self.procs:
            if p.poll() is None:
                p.kill()
        for p in self.procs:
            with contextlib.suppress(subprocess.TimeoutExpired):
                p.wait(5)
        self.procs = []

    def __enter__(self) -> CpuLoad:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()


def _stat(pid: int) -> list[str]:
    """The fields of /proc/PID/stat after the command name (empty once the process is gone)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()
    except OSError:
        return []


def cpu_seconds(pid: int) -> float:
    """User + system CPU seconds process ``pid`` has used (0.0 once it is gone)."""
    fields = _stat(pid)
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK") if fields else 0.0


def niceness(pid: int) -> int | None:
    """Process ``pid``'s nice value (None once it is gone)."""
    fields = _stat(pid)
    return int(fields[16]) if fields else None


def wait_busy(load: CpuLoad, timeout: float = 5.0) -> bool:
    """True once every process of ``load`` has started spinning (used some CPU)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if all(cpu_seconds(p.pid) > 0.02 for p in load.procs):
            return True
        time.sleep(0.05)
    return False

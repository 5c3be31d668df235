"""A simulator behind the fault proxy in a process of its own, for ``bench_links``' long soaks.

Several soaks run at once; with their simulators and proxies in one process they would share one
interpreter lock, and the harness's own delays would pass for the link's. So each soak gets this:
``python -m bench.links_rig_proc SEED`` prints ``port P`` (the proxy's), then ``stop T WHO`` for
every stop that reaches the simulator (``T``: ``time.monotonic()``, one clock for every process;
``WHO``: the sender's identifier, ``client`` without one, ``watchdog`` for the server's own).
Commands on stdin: ``play PROFILE SEED`` (a Wi-Fi profile of ``tests/linkfaults.py``), ``state``
(answers ``state TRANS ROT DRIVES``: the commanded ratios and ratioDrive packets so far), ``reset``
(the robot back where it started: a drive that went on for minutes reached a wall).

``RTMU_LINKS_TRACE=DIR`` in its environment: at exit it writes ``DIR/rig-SEED-PID.json`` with the
three clocks of every status on its way to a client — ``sim``: (when the simulator wrote it, the
client's port as the simulator sees it, the data's name, the simulated time, the simulator thread's
CPU time and run-queue wait so far: the kernel's account of a late one); ``gc``: the process's
garbage collections over 5 ms (each holds every thread); ``proxy``: the proxy's
:attr:`~linkfaults.FaultProxy.trace` (read, due, written); ``stops`` — so a false stop's cause can be
read: a late ``sim`` (its send loop was starved), a proxy that wrote after its due time (the lab's
own stall), or neither (the client read late). ``bench/links_trace.py`` reads them.
"""

from __future__ import annotations

import contextlib
import gc
import json
import os
import sys
import threading
import time
from pathlib import Path

from bench.links_rig import Rig
from linkfaults import PROFILES
from rtmu.base.heap import settle
from rtmu.base.priority import raise_group_priority

ROBOT_PRIORITY = -10
"""The simulator stands for the robot, which does not share the laptop's CPUs: where allowed (root,
``RLIMIT_NICE``), its process runs this many nice levels up, so the laptop's load (other engineers'
work, the bench's spinners) delays the client, not the status the client is waiting for. Its own
session and that session's scheduling group raised too: under autogroup a nice value alone counts
only inside the group, and a traced soak found the simulator's thread waiting 283–392 ms for a
CPU at nice −10 — all three false stops of the "good" Wi-Fi phase."""


GC_PAUSES: list[tuple[float, float, int]] = []
"""(start, seconds, generation) of every collection over 5 ms: it holds every thread of the process."""
_GC_STARTED = [0.0]


def _gc_pause(phase: str, info: dict[str, int]) -> None:
    if phase == "start":
        _GC_STARTED[0] = time.monotonic()
    elif time.monotonic() - _GC_STARTED[0] > 0.005:
        GC_PAUSES.append((_GC_STARTED[0], time.monotonic() - _GC_STARTED[0], info["generation"]))


def _schedstat() -> tuple[float, float]:
    """The calling thread's CPU time and run-queue wait so far, seconds (the kernel's account)."""
    try:
        with open(f"/proc/self/task/{threading.get_native_id()}/schedstat", "rb") as f:
            ran, waited = f.read().split()[:2]
        return int(ran) / 1e9, int(waited) / 1e9
    except (OSError, ValueError):
        return 0.0, 0.0


def main() -> int:
    with contextlib.suppress(OSError):
        os.setpriority(os.PRIO_PROCESS, 0, ROBOT_PRIORITY)
    raise_group_priority(-ROBOT_PRIORITY)  # its own session's group: above the laptop's other sessions
    rig = Rig(int(sys.argv[1]))
    settle()  # as ``rtmu sim`` does: the world's objects out of the collector's full passes
    trace_dir = os.environ.get("RTMU_LINKS_TRACE")
    sent: list[tuple[float, str, str, float, float, float]] = []
    if trace_dir:
        rig.proxy.trace = []
        server = rig.sim.server
        invoke = server.invoke

        def traced(session, number, name, args, *, once):  # type: ignore[no-untyped-def]
            if not once:
                ran, waited = _schedstat()
                port = session.peer.rpartition(":")[2]
                sent.append((time.monotonic(), port, name, server.world.time, ran, waited))
            invoke(session, number, name, args, once=once)

        server.invoke = traced  # type: ignore[method-assign]
        gc.callbacks.append(_gc_pause)
    lock = threading.Lock()

    def say(line: str) -> None:
        with lock:
            sys.stdout.write(line + "\n")
            sys.stdout.flush()

    def report() -> None:
        seen = 0
        while not done.wait(0.002):
            stops = rig.stops
            for at, who in stops[seen:]:
                say(f"stop {at:.6f} {who or 'client'}")
            seen = len(stops)

    done = threading.Event()
    threading.Thread(target=report, daemon=True).start()
    say(f"port {rig.proxy.port}")
    try:
        for line in sys.stdin:
            words = line.split()
            if not words:
                continue
            if words[0] == "play":
                rig.proxy.play(PROFILES[words[1]], seed=int(words[2]))
            elif words[0] == "reset":
                rig.sim.call(rig.sim.server.reset_pose)
            elif words[0] == "state":
                snap = rig.sim.snapshot()
                drives = rig.sim.server.world.ratio_drives_received
                say(f"state {snap.trans_ratio:g} {snap.rot_ratio:g} {drives}")
    finally:
        done.set()
        rig.close()
        if trace_dir:
            out = Path(trace_dir) / f"rig-{sys.argv[1]}-{os.getpid()}.json"
            record = {"sim": sent, "proxy": rig.proxy.trace, "stops": rig.stops, "gc": GC_PAUSES}
            out.write_text(json.dumps(record))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Keep the drive lease about the operator, not the scheduler.

The lease lapses when the thread that renews it (the window's UI thread, 10 Hz while a key is
held) has not done so for :data:`~rtmu.client.lease.LEASE_TTL` — meant for a window that froze.
On a busy laptop the same thread is often merely *waiting for a core*: runnable, in the kernel's
run queue, for 300 ms and more while other programs run. That is no freeze — nothing of ours is
stuck, the key state is read as soon as it gets a core — yet it stopped the robot every few
seconds at a load average of 7–12.

:class:`LeaseKeeper` tells the two apart with the kernel's own account
(``/proc/self/task/TID/schedstat``: time spent runnable but not running). From a thread of its
own, every :data:`PERIOD`, it moves the lease's renewal forward by exactly the time the renewing
thread has spent waiting for a CPU since it last renewed — so a starved thread's lease lives, and
a thread that is busy (its own work, a long redraw), blocked (a lock, a GIL held elsewhere) or
stopped gets no credit and its lease lapses as before. Never beyond :data:`STARVED_LIMIT` after
the real renewal: a machine that cannot run our UI for a second stops the robot anyway.

It renews nothing by itself: a lease that was never granted, was released, ended or has lapsed
stays so (``DriveLease.extend``). The cost — a release made while the UI thread waits for a core
is seen only when it runs, so the robot may drive up to that wait longer — is measured by
``bench/bench_links.py`` (``links.release_during_freeze_mm``).

The keeper also beats for that thread to the guardian with the same credited time, so the
guardian judges the UI by the same rule (``rtmu.guardian``). Where the system allows it (root,
or ``RLIMIT_NICE``), :func:`raise_priority` gives the keeper and the network thread a few nice
levels over the UI: they do little, and must do it on time.
"""

from __future__ import annotations

import contextlib
import os
import threading
from collections.abc import Callable

from .lease import DriveLease

PERIOD = 0.05
"""Seconds between the keeper's looks (well under the lease's 0.3 s)."""
STARVED_LIMIT = 1.0
"""At most this many seconds after the renewing thread's last real renewal does the keeper credit it."""
PRIORITY_BOOST = 5
"""Nice levels :func:`raise_priority` asks for (granted only where the system allows)."""


def runqueue_wait(tid: int) -> float | None:
    """Seconds thread ``tid`` of this process has spent runnable but not running (None: unknown)."""
    try:
        with open(f"/proc/self/task/{tid}/schedstat", "rb") as f:
            return int(f.read().split()[1]) / 1e9
    except (OSError, IndexError, ValueError):
        return None


def raise_priority(boost: int = PRIORITY_BOOST) -> bool:
    """Lower the calling thread's nice value by ``boost`` where allowed; True if it was."""
    tid = threading.get_native_id()
    with contextlib.suppress(OSError, AttributeError):
        current = os.getpriority(os.PRIO_PROCESS, tid)
        os.setpriority(os.PRIO_PROCESS, tid, max(-20, current - boost))
        return True
    return False


class LeaseKeeper:
    """Credits the lease's renewing thread with its run-queue waits; see the module notes."""

    def __init__(
        self,
        lease: DriveLease,
        *,
        beat: Callable[[float], None] | None = None,
        wait_of: Callable[[int], float | None] = runqueue_wait,
        starved_limit: float = STARVED_LIMIT,
        period: float = PERIOD,
    ) -> None:
        self.lease = lease
        self.beat = beat
        """``beat(at)``: a heartbeat for the renewing thread at its credited time (the guardian's)."""
        self.wait_of = wait_of
        self.starved_limit = starved_limit
        self.period = period
        self.credited = 0.0
        """Seconds of run-queue wait credited so far (what would have been false stops)."""
        self.boosted = False
        """Whether the keeper's thread got its higher priority."""
        self._seen_renewal: float | None = None
        self._wait_then: float | None = None
        self._closed = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self) -> LeaseKeeper:
        self._thread = threading.Thread(target=self._run, name="rtmu-lease-keeper", daemon=True)
        self._thread.start()
        return self

    def close(self) -> None:
        self._closed.set()
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(1.0)

    def _run(self) -> None:
        self.boosted = raise_priority()
        while not self._closed.wait(self.period):
            try:
                self.step(self.lease.clock())
            except Exception:  # never let a bad read end the thread that keeps leases fair
                continue

    def step(self, now: float) -> None:
        """One look (the thread calls it every :data:`PERIOD`; tests call it with their own clock)."""
        renewed = self.lease.last_renewal()
        if renewed is None:
            self._seen_renewal = None
            return
        at, tid = renewed
        wait = self.wait_of(tid)
        if at != self._seen_renewal:  # a real renewal since the last look: measure from it
            self._seen_renewal, self._wait_then = at, wait
            return
        if wait is None or self._wait_then is None or now - at > self.starved_limit:
            return
        credit = max(0.0, wait - self._wait_then)
        if credit <= 0.0:
            return
        effective = min(now, at + credit)
        if self.lease.extend(effective):
            self.credited = max(self.credited, credit)
            if self.beat is not None:
                self.beat(effective)

"""Keep the drive lease about the operator, not the scheduler.

The lease lapses when the thread that renews it (the window's UI thread, 10 Hz while a key is
held) has not done so for :data:`~rtmu.client.lease.LEASE_TTL` — meant for a window that froze.
On a busy laptop the same thread is often merely *waiting for a core*: runnable, in the kernel's
run queue, for 300 ms and more while other programs run. That is no freeze — nothing of ours is
stuck, the key state is read as soon as it gets a core — yet it stopped the robot every few
seconds at a load average of 7–12.

:class:`LeaseKeeper` tells the two apart with the kernel's account of the renewing thread
(``/proc/self/task/TID/stat`` and ``schedstat``: runnable or not, CPU time used;
:class:`RunQueueMeter`). From a thread of its own, every :data:`PERIOD`, it moves the lease's
renewal forward by the time the renewing thread has spent waiting for a CPU since it last
renewed — so a starved thread's lease lives, and a thread that is busy (its own work, a long
redraw), blocked (a lock, a GIL held elsewhere) or stopped gets no credit and its lease lapses
as before. Never beyond :data:`STARVED_LIMIT` after
the real renewal: a machine that cannot run our UI for a second stops the robot anyway.

It renews nothing by itself: a lease that was never granted, was released or ended stays so
(``DriveLease.extend``). A lease found past its time is judged with the scheduler's account
before anyone acts on it (``DriveLease.before_lapse``): if the renewer only waited for a CPU, it
lives; otherwise it lapses, is ended, and never comes back. The cost — a release made while the
UI thread waits for a core is seen only when it runs, so the robot may drive up to that wait
longer — is measured by ``bench/bench_links.py`` (``links.release_during_freeze_mm``).

The keeper also beats for that thread to the guardian with the same credited time, so the
guardian judges the UI by the same rule (``rtmu.guardian``). Where the system allows it,
:func:`~rtmu.base.priority.raise_priority` gives the keeper and the network thread a few nice
levels over the UI: they do little, and must do it on time.
"""

from __future__ import annotations

import contextlib
import logging
import os
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

from ..base import link_timing
from ..base.priority import raise_priority
from .lease import DriveLease

log = logging.getLogger(__name__)

PERIOD = 0.05
"""Seconds between the keeper's looks (well under the lease's 0.3 s)."""
IDLE_WAIT = 5.0
"""Seconds a keeper with no lease sleeps between looks if nothing wakes it (a renewal always does)."""
STARVED_LIMIT = 1.0
"""At most this many seconds after the renewing thread's last real renewal does the keeper credit it."""
CREDITING = link_timing.LEARNING
"""False under ``RTMU_LINK_TIMING=fixed``: no keeper, the lease lapses as it did before."""


@dataclass(frozen=True, slots=True)
class ThreadSample:
    """One look at a thread in ``/proc``: runnable now, CPU time so far, run-queue delay counted so far."""

    runnable: bool
    ran: float
    delayed: float


_PROC_FILES: dict[int, tuple[int, int]] = {}
"""Per thread id, its ``stat`` and ``schedstat`` files, kept open: a look re-reads them from the start
(``pread``; the kernel writes them anew), where opening both 30 times a second while driving was
most of a look's cost. A thread that ended fails its read and is forgotten (its id may come back)."""
_PROC_LOCK = threading.Lock()
"""The UI thread and the keeper both look: one look at a time, so no file is closed under a read
(its number could already name another file of the process)."""


def _proc_files(tid: int) -> tuple[int, int]:
    files = _PROC_FILES.get(tid)
    if files is None:
        stat = os.open(f"/proc/self/task/{tid}/stat", os.O_RDONLY | os.O_CLOEXEC)
        try:
            sched = os.open(f"/proc/self/task/{tid}/schedstat", os.O_RDONLY | os.O_CLOEXEC)
        except OSError:
            os.close(stat)
            raise
        files = _PROC_FILES[tid] = (stat, sched)
    return files


def _forget(tid: int) -> None:
    for fd in _PROC_FILES.pop(tid, ()):
        with contextlib.suppress(OSError):
            os.close(fd)


def _thread_sample(tid: int) -> ThreadSample | None:
    with _PROC_LOCK:
        try:
            stat, sched = _proc_files(tid)
            state = os.pread(stat, 1024, 0).rsplit(b")", 1)[1].split()[0]
            ran, delayed = os.pread(sched, 256, 0).split()[:2]
        except (OSError, IndexError, ValueError):
            _forget(tid)
            return None
    return ThreadSample(state == b"R", int(ran) / 1e9, int(delayed) / 1e9)


class RunQueueMeter:
    """How long a thread has waited for a CPU, counted as it happens.

    The kernel counts a thread's run-queue delay (schedstat) exactly, but only once the waiting
    thread runs again — nothing of a wait still going on. So each call also looks at the thread
    now: when two looks in a row find it runnable (``R``) and it has run not at all in between
    (neither its CPU time nor its counted delay moved), it waited for a CPU the whole time; that
    time is added until the kernel's count takes over. A sleeping or blocked thread (a lock, the
    GIL, I/O) earns nothing, and nothing is counted twice.
    """

    def __init__(self, sample: Callable[[int], ThreadSample | None] = _thread_sample) -> None:
        self.sample = sample
        self._first: dict[int, float] = {}
        self._last: dict[int, tuple[float, ThreadSample]] = {}
        self._pending: dict[int, float] = {}

    def __call__(self, tid: int) -> float | None:
        """Seconds thread ``tid`` has waited for a CPU since this meter first looked at it."""
        got = self.sample(tid)
        if got is None:
            return None
        now = time.monotonic()
        first = self._first.setdefault(tid, got.delayed)
        last = self._last.get(tid)
        self._last[tid] = (now, got)
        pending = self._pending.get(tid, 0.0)
        if last is not None:
            before = last[1]
            if got.ran != before.ran or got.delayed != before.delayed:
                pending = 0.0  # it ran: the kernel has counted that wait now
            elif got.runnable and before.runnable:
                pending += now - last[0]  # runnable at both looks, never ran: waiting all along
        self._pending[tid] = pending
        return got.delayed - first + pending


class LeaseKeeper:
    """Credits the lease's renewing thread with its run-queue waits; see the module notes."""

    def __init__(
        self,
        lease: DriveLease,
        *,
        beat: Callable[[float], None] | None = None,
        wait_of: Callable[[int], float | None] | None = None,
        starved_limit: float = STARVED_LIMIT,
        period: float = PERIOD,
    ) -> None:
        self.lease = lease
        self.beat = beat
        """``beat(at)``: a heartbeat for the renewing thread at its credited time (the guardian's)."""
        self.wait_of = wait_of or RunQueueMeter()
        self.starved_limit = starved_limit
        self.period = period
        self.credited = 0.0
        """Seconds of run-queue wait credited so far (what would have been false stops)."""
        self.boosted = False
        """Whether the keeper's thread got its higher priority."""
        self._seen_renewal: float | None = None
        self._wait_then: float | None = None
        self._lock = threading.Lock()
        """Its own thread and the network thread (``DriveGovernor.before_lapse``) both step it."""
        self._closed = threading.Event()
        self._wake = threading.Event()
        """Set by a grant or renewal (:meth:`renewed`) and by :meth:`close`: a keeper with no lease to
        keep sleeps on it instead of looking 20 times a second at nothing (an idle window's wake-ups)."""
        self._thread: threading.Thread | None = None
        self._told: float | None = None
        """The renewal whose lapse :meth:`before_lapse` last logged (once per lapse)."""
        lease.on_renew = self.renewed  # told of every grant and renewal, on the renewing thread
        lease.before_lapse = self.before_lapse  # and asked before anyone acts on a lapse

    def start(self) -> LeaseKeeper:
        self._thread = threading.Thread(target=self._run, name="rtmu-lease-keeper", daemon=True)
        self._thread.start()
        return self

    def close(self) -> None:
        self._closed.set()
        self._wake.set()
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(1.0)

    def _run(self) -> None:
        self.boosted = raise_priority()
        while not self._closed.is_set():
            if self.lease.last_renewal() is None:  # no live lease: nothing to credit until a grant
                self._wake.wait(IDLE_WAIT)
                self._wake.clear()
                continue
            if self._closed.wait(self.period):
                return
            try:
                self.step(self.lease.clock())
            except Exception:  # never let a bad read end the thread that keeps leases fair
                continue

    def renewed(self) -> None:
        """The renewing thread has just renewed (``DriveLease.on_renew``, on that thread): the wait it
        has had so far is the account to measure its next wait from. Wakes a sleeping keeper."""
        with self._lock:
            renewed = self.lease.last_renewal()
            if renewed is not None:
                self._seen_renewal, self._wait_then = renewed[0], self.wait_of(renewed[1])
        self._wake.set()

    def step(self, now: float) -> None:
        """One look: every :data:`PERIOD` from its thread, and from whichever thread finds the lease
        past its time before acting on it (``DriveLease.before_lapse``): a process whose threads all
        waited behind a starved one catches up first."""
        with self._lock:
            self._step(now)

    def before_lapse(self, now: float) -> None:
        """The lease was found past its time: credit what is due first (:meth:`step`); if it still
        lapses, log what the renewing thread did meanwhile (a false stop's cause, at info level)."""
        self.step(now)
        renewed = self.lease.last_renewal()
        if renewed is None or renewed[0] == self._told:
            return
        self._told = renewed[0]  # (before asking the lease again: its view calls this hook)
        if self.lease.view(now).live:
            self._told = None
            return
        at, tid = renewed
        sample = _thread_sample(tid)
        state = "gone" if sample is None else ("runnable" if sample.runnable else "not runnable")
        with self._lock:
            wait, then = self.wait_of(tid), self._wait_then
        waited = "?" if wait is None or then is None else f"{(wait - then) * 1000:.0f} ms"
        log.info(
            "lease past its time: the renewing thread %d last renewed %.0f ms ago, has waited %s for a "
            "CPU since, and is %s now",
            tid, (now - at) * 1000, waited, state,
        )  # fmt: skip

    def _step(self, now: float) -> None:
        renewed = self.lease.last_renewal()
        if renewed is None:
            self._seen_renewal = None
            return
        at, tid = renewed
        wait = self.wait_of(tid)
        if at != self._seen_renewal:  # a renewal :meth:`renewed` was not told of: measure from now
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

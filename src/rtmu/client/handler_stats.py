"""Subscription handlers called on the network loop, each call counted and timed.

A handler runs on the loop that also sends the stops, so one that is slow holds up every packet behind
it: each call is timed by the wall clock and by the thread's own CPU time (the CPU part tells slow
work — ours to fix — from a machine that did not run us), and a handler that raises is logged and
counted, never fatal. The soak reads these figures (``bench/soak.py``).
"""

from __future__ import annotations

import logging
import time

from .call_values import Handler, Packet

log = logging.getLogger(__name__)

SLOW_HANDLER = 0.01
"""A subscription handler that runs longer than this on the loop is counted and logged (the soak's
promise: no handler over 10 ms on the loop that sends the stops)."""


class HandlerStats:
    """One connection's handler calls: :meth:`call` runs one; the counters say how they went."""

    __slots__ = ("errors", "max_cpu_seconds", "max_seconds", "slow", "slow_cpu")

    def __init__(self) -> None:
        self.errors = 0
        """Exceptions raised by subscription handlers (logged, never fatal)."""
        self.slow = 0
        """Handler calls that took longer than :data:`SLOW_HANDLER` (logged: they delay every packet)."""
        self.max_seconds = 0.0
        """The longest one handler call has held the loop (soak and health figures)."""
        self.max_cpu_seconds = 0.0
        """The most CPU one handler call used: its own work, without time the thread was descheduled."""
        self.slow_cpu = 0
        """Handler calls whose own CPU time went over :data:`SLOW_HANDLER`."""

    def call(self, handler: Handler, packet: Packet) -> None:
        """Run ``handler(packet)``: an exception is logged and counted, a slow call counted and said."""
        started = time.perf_counter()
        started_cpu = time.thread_time()
        try:
            handler(packet)
        except Exception:
            self.errors += 1
            log.exception("handler for %s failed", packet.name)
        spent = time.perf_counter() - started
        cpu = time.thread_time() - started_cpu
        self.max_seconds = max(self.max_seconds, spent)
        self.max_cpu_seconds = max(self.max_cpu_seconds, cpu)
        if cpu > SLOW_HANDLER:
            self.slow_cpu += 1
        if spent > SLOW_HANDLER:  # it held up the loop that sends the stops: say so
            self.slow += 1
            if self.slow <= 10 or self.slow % 1000 == 0:
                # The CPU part tells slow work (ours to fix) from a machine that did not run us.
                log.warning(
                    "the handler for %s took %.0f ms on the network loop (%.0f ms of it on the CPU)",
                    packet.name,
                    spent * 1e3,
                    cpu * 1e3,
                )

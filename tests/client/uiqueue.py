"""A stand-in for the GTK main loop: ``post`` queues, the test thread drains (it is the "UI thread")."""

from __future__ import annotations

import queue
import time
from collections.abc import Callable

from patience import PATIENCE


class UiQueue:
    def __init__(self) -> None:
        self._q: queue.Queue[Callable[[], None]] = queue.Queue()

    def post(self, fn: Callable[[], None]) -> None:
        self._q.put(fn)

    def drain(self) -> int:
        n = 0
        while True:
            try:
                fn = self._q.get_nowait()
            except queue.Empty:
                return n
            fn()
            n += 1

    def wait_for(self, predicate: Callable[[], bool], timeout: float = 5.0) -> None:
        """Run posted callbacks until ``predicate()`` holds; fail after ``timeout`` s (× PATIENCE)."""
        deadline = time.monotonic() + timeout * PATIENCE
        while True:
            self.drain()
            if predicate():
                return
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise AssertionError("condition not reached in time")
            try:
                fn = self._q.get(timeout=min(remaining, 0.05))
            except queue.Empty:
                continue
            fn()


def eventually(predicate: Callable[[], bool], timeout: float = 3.0) -> None:
    """Poll ``predicate`` until it holds (bytes still in flight between threads); fail after ``timeout``
    seconds (× PATIENCE)."""
    deadline = time.monotonic() + timeout * PATIENCE
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError("condition not reached in time")
        time.sleep(0.005)

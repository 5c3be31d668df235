"""Whether the network loop waits for events or works, and since when: its lag, with no timer of its own.

The loop must never block (stops go out on it). A window asks once a second how long the loop has been
busy without returning to wait for the network: a handler stuck for half a second means that drive
commands and stops are not getting out. Watching the selector answers that exactly and at once —
waiting in ``select`` is no lag however long it lasts — where a heartbeat timer had to wake a still
loop ten times a second to be able to tell (issue 28).
"""

from __future__ import annotations

import selectors
import time
from collections.abc import Callable
from typing import Any


class WatchedSelector(selectors.DefaultSelector):
    """The platform's selector, noting when the loop stops waiting and starts working."""

    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        super().__init__()
        self.clock = clock
        self._working_since: float | None = None
        """When the loop last came back from waiting; None while it waits (or before it first ran)."""

    def select(self, timeout: float | None = None) -> list[tuple[selectors.SelectorKey, Any]]:
        self._working_since = None
        try:
            return super().select(timeout)
        finally:
            self._working_since = self.clock()

    def busy_for(self) -> float:
        """Seconds the loop has been working since it last waited (0 while it waits). Any thread."""
        since = self._working_since
        return 0.0 if since is None else max(0.0, self.clock() - since)

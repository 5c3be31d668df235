"""The wait of a command that stays connected until ``--seconds`` or a signal (record, bridge).

Meanwhile it asks for camera pictures at ``--camera-hz`` where the server offers one, and,
for a command that may drive, beats for the guardian so a hung process is stopped.
"""

from __future__ import annotations

import concurrent.futures
import signal
import threading
import time
from types import TracebackType
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import signal_code

if TYPE_CHECKING:
    from ..client.runner import ClientRunner

IDLE_WAIT = 0.2
"""Longest sleep between passes when nothing else is due (a signal sets ``ended`` anyway)."""


def follow(
    runner: ClientRunner,
    ended: threading.Event,
    *,
    seconds: float | None,
    camera_hz: float,
    beat: float | None = None,
) -> None:
    """Return after ``seconds`` (None: never) or once ``ended`` is set; ``beat``: heartbeat period."""
    from ..client.video_feed import picture_source
    from ..values.intents import RequestPicture

    deadline = None if seconds is None else time.monotonic() + seconds
    period = 1.0 / camera_hz if camera_hz > 0 else None
    next_picture = time.monotonic()
    pending = None
    while not ended.is_set():
        now = time.monotonic()
        if deadline is not None and now >= deadline:
            return
        if beat is not None:
            runner.ui_heartbeat()
        if period is not None and now >= next_picture and (pending is None or pending.done()):
            session = runner.session
            client = session.client if session is not None else None
            if client is not None and picture_source(e.name for e in client.datalist) is not None:
                pending = runner.submit(session.dispatch, RequestPicture())  # type: ignore[union-attr]
                pending.add_done_callback(lambda f: f.cancelled() or f.exception())
            next_picture = max(next_picture + period, now)
        waits = [IDLE_WAIT if beat is None else beat]
        if deadline is not None:
            waits.append(deadline - now)
        if period is not None:
            waits.append(max(0.0, next_picture - now))
        ended.wait(max(0.0, min(waits)))


ENDING_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class EndingSignals:
    """``with EndingSignals() as ending:`` Ctrl-C, SIGTERM and SIGHUP set ``ending.event`` (the command
    finishes its file or its bridge and ends); ``ending.exit_code`` is then 128 + the first one's number,
    as every other command exits after a signal. The previous handlers come back at the end."""

    def __init__(self) -> None:
        self.event = threading.Event()
        self.signum: int | None = None
        self._previous: dict[int, Any] = {}

    def _caught(self, signum: int, _frame: object) -> None:
        if self.signum is None:
            self.signum = signum
        self.event.set()

    def __enter__(self) -> EndingSignals:
        self._previous = {s: signal.signal(s, self._caught) for s in ENDING_SIGNALS}
        return self

    def __exit__(self, *exc: type[BaseException] | BaseException | TracebackType | None) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)

    @property
    def exit_code(self) -> int | None:
        """128 + N after signal N; None when no signal came."""
        return None if self.signum is None else signal_code(self.signum)


def until_connected(future: concurrent.futures.Future[None], ended: threading.Event, timeout: float) -> bool:
    """Wait for the runner's connect: True once connected, False if ``ended`` (a signal) came first.

    Its failure is raised as the future's exception; ``ClientTimeout`` after ``timeout`` s.
    """
    from ..client.errors import ClientTimeout

    deadline = time.monotonic() + timeout
    while not ended.is_set():
        try:
            future.result(min(IDLE_WAIT, max(0.0, deadline - time.monotonic())))
            return True
        except concurrent.futures.TimeoutError:
            if future.done():  # it failed with a timeout of its own (ClientTimeout is a TimeoutError)
                raise
            if time.monotonic() >= deadline:
                raise ClientTimeout(f"not connected within {timeout:g} s") from None
    future.cancel()
    return False

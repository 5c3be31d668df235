"""The wait of a command that stays connected until ``--seconds`` or a signal (record, bridge).

Meanwhile it asks for camera pictures at ``--camera-hz`` where the server offers one, and,
for a command that may drive, beats for the guardian so a hung process is stopped.
"""

from __future__ import annotations

import threading
import time

from ..client.runner import ClientRunner
from ..client.video_feed import picture_source
from ..values.intents import RequestPicture

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

"""Camera frames served the way ARIA's video forwarder serves them: one shared frame, about 10 per second.

ARIA's ``ArHybridForwarderVideo`` asks its camera for a picture about every
100 ms and answers every client's picture request with the latest frame it
holds, so a client that asks every cycle costs the robot nothing extra. The
simulator does the same for each picture size, in simulated time:

* a request is answered at once with the latest frame when that frame is
  younger than :data:`FRAME_PERIOD_S`;
* otherwise a new frame is made — as a real camera delivers a fresh frame at its rate
  whatever the robot does: a view that did not change is not ray-cast again, its
  picture gets fresh sensor noise and a new time stamp (:func:`camera.refresh_frame`);
  a new view is rendered — and every request
  for that size that arrives before it is ready waits for it and gets it
  (rather than the stale one: a client that asks after the period has passed
  sees a picture from after its request). At most one render per size is in
  flight.

The JPEG quality is that of the latest request that asked for one, applied to
the next frame — the forwarder likewise passes the last client's argument on
to its camera. In real-time mode the render (ray casting and JPEG encoding)
runs on one worker thread, so the server's 10 ms cycle keeps its timing (numpy
and Pillow release the GIL for most of the work); on the manual clock it runs
inline unless asked otherwise, so tests stay deterministic.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import logging
from collections.abc import Callable, Hashable
from dataclasses import dataclass
from functools import partial

import numpy as np

from .camera import View, refresh_frame, render_frame

log = logging.getLogger("rtmu.sim")

FRAME_PERIOD_S = 0.1
"""The forwarder's polling period: at most one new frame per size per 100 ms of simulated time
(the default; ``SimConfig.camera_hz`` sets another)."""
DEFAULT_QUALITY = 75
MAX_OWED_PER_WAITER = 4
"""Replies owed to one requester (one client's data) while a frame renders; more are dropped, like UDP."""

Deliver = Callable[[bytes], None]
Size = tuple[int, int]


@dataclass(frozen=True, slots=True)
class Frame:
    view: View
    jpeg: bytes
    taken_at: float
    """Simulated time of the view it shows."""
    pixels: np.ndarray
    """The view's rendered scene, reused (with fresh noise) while the view does not change."""


@dataclass(slots=True)
class _Waiter:
    deliver: Deliver
    owed: int = 1


class VideoFeed:
    """The latest frame per picture size, renders at most every :data:`FRAME_PERIOD_S`, and who waits."""

    def __init__(self, *, threaded: bool, period: float = FRAME_PERIOD_S) -> None:
        self.period = period
        """Seconds of simulated time a frame is served before a new one is rendered."""
        self._executor = (
            concurrent.futures.ThreadPoolExecutor(max_workers=1, thread_name_prefix="rtmu-sim-video")
            if threaded
            else None
        )
        self._latest: dict[Size, Frame] = {}
        self._in_flight: dict[Size, asyncio.Future[tuple[np.ndarray, bytes]]] = {}
        self._waiting: dict[Size, dict[Hashable, _Waiter]] = {}
        self.quality = DEFAULT_QUALITY
        self.renders = 0
        """Frames rendered (ray-cast) since the start (for tests and the benchmark)."""
        self.refreshes = 0
        """Fresh frames of a view that did not change (noise and stamp only)."""

    @property
    def executor(self) -> concurrent.futures.ThreadPoolExecutor | None:
        """The single render worker (None when rendering inline)."""
        return self._executor

    def picture(
        self, view: View, now: float, quality: int | None, requester: Hashable, deliver: Deliver
    ) -> bytes | None:
        """The JPEG for ``view`` now, or None when it is being rendered: then ``deliver`` gets it later.

        ``requester`` identifies who asks (a client and data number): repeated asks from one requester
        while a frame renders are answered together, up to :data:`MAX_OWED_PER_WAITER` replies.
        """
        if quality is not None:
            self.quality = min(max(int(quality), 1), 95)
        size = view.size
        latest = self._latest.get(size)
        if latest is not None and now - latest.taken_at < self.period - 1e-9:
            return latest.jpeg
        if latest is not None and latest.view == view:
            job = partial(refresh_frame, latest.pixels, self.quality, self.renders + self.refreshes)
        else:
            job = partial(render_frame, view, self.quality)
        if self._executor is None:
            return self._store(view, now, job())
        waiting = self._waiting.setdefault(size, {})
        waiter = waiting.get(requester)
        if waiter is None:
            waiting[requester] = _Waiter(deliver)
        else:
            waiter.owed = min(waiter.owed + 1, MAX_OWED_PER_WAITER)
        if size not in self._in_flight:
            loop = asyncio.get_running_loop()
            future = loop.run_in_executor(self._executor, job)
            self._in_flight[size] = future
            future.add_done_callback(lambda f: self._rendered(view, now, f))
        return None

    def _store(self, view: View, now: float, made: tuple[np.ndarray, bytes]) -> bytes:
        pixels, jpeg = made
        latest = self._latest.get(view.size)
        if latest is not None and latest.pixels is pixels:
            self.refreshes += 1
        else:
            self.renders += 1
        self._latest[view.size] = Frame(view, jpeg, now, pixels)
        return jpeg

    def _rendered(self, view: View, now: float, future: asyncio.Future[tuple[np.ndarray, bytes]]) -> None:
        size = view.size
        self._in_flight.pop(size, None)
        waiting = self._waiting.pop(size, {})
        if future.cancelled():
            return
        error = future.exception()
        if error is not None:
            log.error("camera render failed", exc_info=error)
            return
        jpeg = self._store(view, now, future.result())
        for waiter in waiting.values():
            for _ in range(waiter.owed):
                waiter.deliver(jpeg)

    async def settle(self, timeout: float = 2.0) -> None:
        """Wait for renders in flight (before a server stops), so no worker outlives its loop's use."""
        pending = list(self._in_flight.values())
        if pending:
            await asyncio.wait(pending, timeout=timeout)

    def close(self) -> None:
        """Stop the worker; frames still queued are dropped."""
        if self._executor is not None:
            self._executor.shutdown(wait=False, cancel_futures=True)

"""Live video for the operator session: the :class:`~.video_feed.VideoFeed` loop, kept across reconnects.

It hangs off :class:`~.session.Session` like ``nav_session`` does: the session
tells it when a connection opens and ends, and it publishes every new frame as
the model's ``camera`` part (a :class:`~rtmu.values.state.CameraImage` carrying its
render stamp and the live figures), so the window's existing JPEG thread decodes
it into textures. What the operator asked (live or not, paused, rate, quality)
outlives the connection: after a reconnect the video resumes by itself.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Coroutine
from typing import Any

from ..values.state import CameraChanged, CameraImage, StateChange
from .connection import AriaClient
from .errors import ServerClosed
from .video_feed import DEFAULT_FPS, LiveFrame, VideoFeed, clamp_fps, video_source


class LiveVideo:
    """Starts, pauses and stops the request loop on the network thread; publishes frames."""

    def __init__(
        self,
        publish: Callable[[StateChange], None],
        spawn: Callable[[Coroutine[Any, Any, Any], str], None],
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._publish = publish
        self._spawn = spawn
        self._clock = clock
        self.client: AriaClient | None = None
        self.feed: VideoFeed | None = None
        self.wanted = False
        self.paused = False
        self.fps = DEFAULT_FPS
        self.quality: int | None = None
        self.sequence_base = 1_000_000_000
        """Live frames number from here, so they never equal a single picture's sequence."""

    # -- the session's hooks ---------------------------------------------------------------------
    def connected(self, client: AriaClient) -> None:
        self.client = client
        self.feed = None
        if self.wanted:
            self._start()

    def disconnected(self) -> None:
        """The session cancels its tasks (the loop among them); forget the feed, keep the wish."""
        self.client = None
        self.feed = None

    # -- the operator's controls (network loop) -------------------------------------------------
    def start(self, fps: float | None = None, quality: int | None = None) -> None:
        """Play (NotSupported when the server has no camera); a second call only changes the settings."""
        if fps is not None:
            self.fps = clamp_fps(fps)
        if quality is not None:
            self.quality = min(max(int(quality), 0), 100)
        self.wanted = True
        if self.feed is not None:
            self.feed.set_fps(self.fps)
            self.feed.set_quality(self.quality)
            return
        if self.client is None or not self.client.connected:
            raise ServerClosed("not connected")
        self._start()

    def stop(self) -> None:
        self.wanted = False
        self.paused = False
        feed, self.feed = self.feed, None
        if feed is not None:
            feed.stop()

    def shown(self, sequence: int) -> None:
        """The window has drawn (or dropped) live frame ``sequence``: the loop may ask for the next."""
        if self.feed is not None:
            self.feed.shown(sequence - self.sequence_base)

    def pause(self, paused: bool) -> None:
        self.paused = paused
        if self.feed is not None:
            self.feed.pause(paused)

    # -- inside ---------------------------------------------------------------------------------
    def _start(self) -> None:
        client = self.client
        assert client is not None
        source = video_source(client)
        feed = VideoFeed(client, source, self._frame, fps=self.fps, quality=self.quality, max_pending=1)
        feed.pause(self.paused)
        self.feed = feed
        self._spawn(self._run(feed), "video")

    async def _run(self, feed: VideoFeed) -> None:
        try:
            await feed.run()
        finally:
            if self.feed is feed:
                self.feed = None

    def _frame(self, frame: LiveFrame) -> None:
        feed = self.feed
        self._publish(
            CameraChanged(
                CameraImage(
                    jpeg=frame.jpeg,
                    width=frame.width,
                    height=frame.height,
                    source=frame.source,
                    received_at=self._clock(),
                    sequence=self.sequence_base + frame.sequence,
                    stamp_ns=frame.stamp_ns,
                    video=None if feed is None else feed.status(),
                )
            )
        )

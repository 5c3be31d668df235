"""The session's camera: single pictures, and live video kept across reconnects.

Every new picture — one asked for (:class:`RequestPicture`) or one of the live loop's frames
(:class:`~.video_feed.VideoFeed`) — is published as the model's ``camera`` part (a
:class:`~rtmu.values.state.CameraImage` carrying its render stamp and, for live frames, the loop's
frame number and figures), so the window's JPEG thread decodes it into textures. What the operator
asked (live or not, paused, rate, quality) outlives the connection: after a reconnect the video
resumes by itself.
"""

from __future__ import annotations

from typing import ClassVar

from ..protocol.payloads import Side, payload_type_for
from ..values.intents import Intent, PauseVideo, RequestPicture, StartVideo, StopVideo, VideoShown
from ..values.state import CameraChanged, CameraImage
from .connection import AriaClient
from .errors import MalformedReply, NotSupported, ServerClosed
from .feed import Feed, FeedContext
from .video_feed import DEFAULT_FPS, LiveFrame, VideoFeed, clamp_fps, frame_stamp, video_source


class CameraFeed(Feed):
    """Starts, pauses and stops the request loop on the network thread; publishes every picture."""

    handles: ClassVar[tuple[type[Intent], ...]] = (
        RequestPicture,
        StartVideo,
        StopVideo,
        PauseVideo,
        VideoShown,
    )

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self.client: AriaClient | None = None
        self.feed: VideoFeed | None = None
        self.wanted = False
        self.paused = False
        self.fps = DEFAULT_FPS
        self.quality: int | None = None
        self._sequence = 0
        """One count for pictures and live frames alike: every new picture is a new value."""

    # -- the session's hooks ---------------------------------------------------------------------
    def connected(self, client: AriaClient) -> None:
        self.client = client
        self.feed = None
        if self.wanted:
            self._start()

    def lost(self) -> None:
        """The session cancels its tasks (the loop among them); forget the feed, keep the wish."""
        self.client = None
        self.feed = None

    def disconnected(self) -> None:
        """A new connection (or none) starts without video: the operator asks again."""
        self.lost()
        self._stop()
        self.ctx.publish(CameraChanged(None))

    # -- the operator's intents (network loop) -----------------------------------------------------
    def handle(self, intent: Intent) -> object:
        if isinstance(intent, RequestPicture):
            return self._picture()
        if isinstance(intent, StartVideo):
            self._play(intent.fps, intent.quality)
        elif isinstance(intent, StopVideo):
            self._stop()
        elif isinstance(intent, PauseVideo):
            self.paused = intent.paused
            if self.feed is not None:
                self.feed.pause(intent.paused)
        elif isinstance(intent, VideoShown) and self.feed is not None:
            self.feed.shown(intent.sequence)
        return None

    def _play(self, fps: float | None, quality: int | None) -> None:
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

    def _stop(self) -> None:
        self.wanted = False
        self.paused = False
        feed, self.feed = self.feed, None
        if feed is not None:
            feed.stop()

    async def _picture(self) -> CameraImage:
        """One camera picture; also published as the model's ``camera`` part."""
        client = self.require()
        source = video_source(client)
        reply = await client.request_once(source, timeout=self.ctx.config.reply_timeout)
        if payload_type_for(source, Side.REPLY) is None:
            raise NotSupported(source, f"RTMU cannot decode {source!r} pictures")
        picture = self.ctx.decode(source, reply.payload)
        if picture is None:
            raise MalformedReply(f"the {source} picture is malformed")
        self._sequence += 1
        jpeg = bytes(picture.jpeg)
        image = CameraImage(
            jpeg=jpeg,
            width=int(picture.width),
            height=int(picture.height),
            source=source,
            received_at=reply.received_at,
            sequence=self._sequence,
            stamp_ns=frame_stamp(jpeg),
        )
        self.ctx.publish(CameraChanged(image))
        return image

    # -- inside ---------------------------------------------------------------------------------
    def _start(self) -> None:
        client = self.client
        assert client is not None
        source = video_source(client)
        feed = VideoFeed(client, source, self._frame, fps=self.fps, quality=self.quality, max_pending=1)
        feed.pause(self.paused)
        self.feed = feed
        self.ctx.spawn(self._run(feed), "video")

    async def _run(self, feed: VideoFeed) -> None:
        try:
            await feed.run()
        finally:
            if self.feed is feed:
                self.feed = None

    def _frame(self, frame: LiveFrame) -> None:
        feed = self.feed
        self._sequence += 1
        self.ctx.publish(
            CameraChanged(
                CameraImage(
                    jpeg=frame.jpeg,
                    width=frame.width,
                    height=frame.height,
                    source=frame.source,
                    received_at=self.ctx.clock(),
                    sequence=self._sequence,
                    stamp_ns=frame.stamp_ns,
                    video=None if feed is None else feed.status(),
                    frame=frame.sequence,
                )
            )
        )

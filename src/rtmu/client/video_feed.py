"""Live video: one picture request in flight at a time, the next sent when a frame arrives.

ARIA offers no video stream, only a picture per request (``getPicture<Name>``,
else ``sendVideo``), so "video" is a loop on the network thread: ask, wait for
the frame, hand it on, ask again — never more than one request in flight, and
no sooner than the frame-rate setting allows. The loop only checks a frame's
structure (cheap, bounded) and reads its render stamp; decoding into pixels is
the consumer's job on its own worker thread (the window's JPEG thread, the
CLI's executor), so neither the network loop nor the GTK thread decodes.

The simulator stamps each frame with a JPEG comment ``RTMU-T=<wall-clock ns>``
(its render time), so the age of a frame is measured end to end. When the round
trip grows or frames age past a limit, the :class:`RateGovernor` halves the rate
and says why; it climbs back once the link is healthy again.
"""

from __future__ import annotations

import asyncio
import statistics
import time
import zlib
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

from ..protocol.errors import ProtocolError
from ..protocol.payloads.camera import VideoFrame
from ..values.intents import picture_source
from ..values.state import VideoStatus
from .connection import AriaClient
from .errors import ClientError, ClientTimeout, NotSupported, ServerClosed
from .jpeg_bounds import MAX_SIDE, STAMP_PREFIX, fill_problem, read_header

__all__ = ["MAX_SIDE", "STAMP_PREFIX", "BadFrame", "VideoFeed", "check_frame", "frame_stamp", "parse_frame"]
MAX_FPS = 30.0
MIN_FPS = 0.5
DEFAULT_FPS = 15.0
DEFAULT_QUALITY: int | None = None
"""None: leave the quality argument out (the server's own choice), as ARIA's example client does."""
RTT_LIMIT_S = 0.5
AGE_LIMIT_S = 1.0
RECOVER_AFTER_S = 3.0
REQUEST_TIMEOUT_S = 5.0
CONSUMER_WAIT_S = 1.0
"""Longest the loop waits for the consumer to show a frame before asking for the next anyway."""
STATS_WINDOW_S = 2.0
MAX_AGES = 1000


class BadFrame(ValueError):
    """A frame that is not a sane JPEG picture; its text says why in plain words."""


def frame_stamp(jpeg: bytes) -> int | None:
    """The render time (wall-clock ns) in the frame's ``RTMU-T=`` comment, or None when it has none."""
    return read_header(jpeg).stamp


def check_frame(jpeg: bytes, width: int, height: int) -> tuple[int | None, tuple[int, int]]:
    """The frame's stamp and true size; :class:`BadFrame` for bytes that cannot be a sane picture.

    Cheap enough for the network loop: no pixels are decoded, only the header is walked.
    """
    if width > MAX_SIDE or height > MAX_SIDE:
        raise BadFrame(f"the server claims a {width}x{height} frame, over the {MAX_SIDE}x{MAX_SIDE} limit")
    if not jpeg.startswith(b"\xff\xd8"):
        raise BadFrame(f"the {len(jpeg)} bytes received are not a JPEG picture")
    if not jpeg.endswith(b"\xff\xd9"):
        raise BadFrame(f"the picture is cut short ({len(jpeg)} bytes, no end marker)")
    header = read_header(jpeg)
    size = header.size
    if size is not None and min(size) > 0 and max(size) <= MAX_SIDE and (width, height) not in ((0, 0), size):
        raise BadFrame(f"the server says {width}x{height} but the picture is {size[0]}x{size[1]}")
    problem = fill_problem(jpeg, header)  # its data can fill what it declares (jpeg_bounds)
    if problem is not None or size is None:
        raise BadFrame(problem or "the picture has no frame header")
    return header.stamp, size


def parse_frame(payload: bytes) -> tuple[VideoFrame, int | None]:
    """A ``sendVideo`` / ``getPicture…`` reply payload → (frame, stamp); :class:`BadFrame` if unusable.

    The forwarder's 2 trailing bytes after the end marker are split off by :class:`VideoFrame`.
    """
    try:
        frame = VideoFrame.decode(payload)
    except ProtocolError as exc:
        raise BadFrame(f"the frame packet is malformed: {exc}") from None
    stamp, _ = check_frame(frame.jpeg, frame.width, frame.height)
    return frame, stamp


@dataclass(frozen=True, slots=True)
class LiveFrame:
    """One new frame for a consumer: bytes, size, where it came from and its timing."""

    jpeg: bytes = field(repr=False)
    width: int
    height: int
    source: str
    sequence: int
    received_ns: int
    """Wall-clock ns when its last byte arrived."""
    stamp_ns: int | None
    """Wall-clock ns the server rendered it (None: the server does not stamp)."""
    round_trip_s: float


class RateGovernor:
    """The interval between requests: the frame-rate setting, stretched while the link is slow."""

    def __init__(self, fps: float, *, rtt_limit: float = RTT_LIMIT_S, age_limit: float = AGE_LIMIT_S) -> None:
        self.target_fps = clamp_fps(fps)
        self.rtt_limit = rtt_limit
        self.age_limit = age_limit
        self.factor = 1
        """The rate is ``target_fps / factor``; 1 when healthy."""
        self.reason = ""
        self._healthy_since: float | None = None

    @property
    def rate_fps(self) -> float:
        return self.target_fps / self.factor

    @property
    def interval(self) -> float:
        return 1.0 / self.rate_fps

    def observe(self, now: float, rtt: float, age: float | None) -> None:
        """One frame's round trip and age (seconds); halve the rate when either is past its limit."""
        slow = ""
        if rtt > self.rtt_limit:
            slow = f"round trip {rtt * 1000:.0f} ms"
        elif age is not None and age > self.age_limit:
            slow = f"frames {age * 1000:.0f} ms old"
        if slow:
            self._healthy_since = None
            if self.factor < 32 and self.rate_fps / 2 >= MIN_FPS / 2:
                self.factor *= 2
            self.reason = f"slowed to {self.rate_fps:.1f} fps: {slow}"
            return
        if self.factor == 1:
            self.reason = ""
            return
        if self._healthy_since is None:
            self._healthy_since = now
        elif now - self._healthy_since >= RECOVER_AFTER_S:
            self.factor //= 2
            self._healthy_since = now
            self.reason = "" if self.factor == 1 else f"recovering: {self.rate_fps:.1f} fps"

    def set_fps(self, fps: float) -> None:
        self.target_fps = clamp_fps(fps)


def clamp_fps(fps: float) -> float:
    return min(max(float(fps), MIN_FPS), MAX_FPS)


class FrameStats:
    """Frames, bytes and ages over a sliding window (rates) and overall (percentiles, bounded)."""

    def __init__(self, window: float = STATS_WINDOW_S) -> None:
        self.window = window
        self._recent: deque[tuple[float, int]] = deque()
        self.frames = 0
        self.bytes = 0
        self.repeats = 0
        self.dropped = 0
        self.ages_ms: deque[float] = deque(maxlen=MAX_AGES)
        self.last_age_ms: float | None = None

    def add(self, now: float, size: int, age_ms: float | None) -> None:
        self.frames += 1
        self.bytes += size
        self._recent.append((now, size))
        if age_ms is not None:
            self.ages_ms.append(age_ms)
            self.last_age_ms = age_ms
        self._trim(now)

    def _trim(self, now: float) -> None:
        while self._recent and now - self._recent[0][0] > self.window:
            self._recent.popleft()

    def rates(self, now: float) -> tuple[float, float]:
        """(frames per second, kB per second) over the window."""
        self._trim(now)
        if not self._recent:
            return 0.0, 0.0
        span = max(now - self._recent[0][0], 1e-3) if len(self._recent) > 1 else self.window
        n = len(self._recent) - 1 if len(self._recent) > 1 else 1
        size = sum(s for _, s in self._recent)
        return n / span, size / 1000.0 / max(span, 1e-3)

    def age_percentile(self, p: float) -> float | None:
        if not self.ages_ms:
            return None
        if len(self.ages_ms) == 1:
            return self.ages_ms[0]
        cuts = statistics.quantiles(self.ages_ms, n=100, method="inclusive")
        return cuts[min(max(int(p) - 1, 0), 98)]


def video_source(client: AriaClient, camera: str | None = None) -> str:
    """``getPicture<camera>`` (the first listed when no camera is named), else ``sendVideo``."""
    if camera is not None:
        name = f"getPicture{camera}"
        if not client.supports(name):
            raise NotSupported(name, f"this server has no camera named {camera!r} ({name})")
        return name
    source = picture_source(e.name for e in client.datalist)
    if source is None:
        raise NotSupported("getPicture", "this server offers no camera pictures (getPicture… or sendVideo)")
    return source


FrameSink = Callable[[LiveFrame], None]
StatusSink = Callable[[VideoStatus], None]


class VideoFeed:
    """The request loop for one connection; sinks run on the network loop and must only hand on.

    ``on_frame`` gets every new frame (a repeat of the previous one — the same stamp or bytes, as a
    forwarder polling its camera slower than we ask returns — is counted, not handed on);
    ``on_status`` gets the caption's figures after every frame, drop or pause.
    """

    def __init__(
        self,
        client: AriaClient,
        source: str,
        on_frame: FrameSink,
        on_status: StatusSink | None = None,
        *,
        fps: float = DEFAULT_FPS,
        quality: int | None = DEFAULT_QUALITY,
        timeout: float = REQUEST_TIMEOUT_S,
        max_pending: int | None = None,
        clock: Callable[[], float] = time.monotonic,
        wall_ns: Callable[[], int] = time.time_ns,
    ) -> None:
        self.client = client
        self.source = source
        self.on_frame = on_frame
        self.on_status = on_status
        self.governor = RateGovernor(fps)
        self.quality = None if quality is None else min(max(int(quality), 0), 100)
        self.timeout = timeout
        self.clock = clock
        self.wall_ns = wall_ns
        self.stats = FrameStats()
        self.note = ""
        self._sequence = 0
        self.max_pending = max_pending
        """Frames handed on but not yet shown before the loop waits (None: never waits). A consumer
        that reports :meth:`shown` gets backpressure: frames never queue up behind a busy UI."""
        self._shown = 0
        self._consumed = asyncio.Event()
        self._last: tuple[int | None, int, int] | None = None
        self._resume = asyncio.Event()
        self._resume.set()
        self._stopped = False

    # -- controls (network loop) ----------------------------------------------------------------
    @property
    def paused(self) -> bool:
        return not self._resume.is_set()

    def pause(self, paused: bool = True) -> None:
        if paused:
            self._resume.clear()
        else:
            self._resume.set()
        self._report()

    def stop(self) -> None:
        self._stopped = True
        self._resume.set()

    def set_fps(self, fps: float) -> None:
        self.governor.set_fps(fps)

    def shown(self, sequence: int) -> None:
        """The consumer has shown (or given up on) frame ``sequence`` and every one before it."""
        if sequence > self._shown:
            self._shown = sequence
            self._consumed.set()

    async def _consumer_ready(self) -> None:
        if self.max_pending is None:
            return
        deadline = self.clock() + CONSUMER_WAIT_S
        while self._sequence - self._shown > self.max_pending and not self._stopped:
            self._consumed.clear()
            left = deadline - self.clock()
            if left <= 0:
                return  # a stalled consumer must not freeze the video for ever: go on, slowly
            try:
                await asyncio.wait_for(self._consumed.wait(), left)
            except TimeoutError:
                return

    def set_quality(self, quality: int | None) -> None:
        self.quality = None if quality is None else min(max(int(quality), 0), 100)

    # -- the loop ------------------------------------------------------------------------------
    async def run(self, seconds: float | None = None) -> None:
        """Ask for frames until stopped, ``seconds`` pass, or the connection ends (ServerClosed)."""
        end = None if seconds is None else self.clock() + seconds
        while not self._stopped:
            await self._resume.wait()
            await self._consumer_ready()
            if self._stopped or (end is not None and self.clock() >= end):
                break
            started = self.clock()
            args: tuple[bytes, ...] = () if self.quality is None else (bytes([self.quality]),)
            try:
                reply = await self.client.request_once(self.source, *args, timeout=self.timeout)
            except ClientTimeout as exc:
                self._drop(f"no frame: {exc}")
                self.governor.observe(self.clock(), self.clock() - started, None)
                continue
            except ServerClosed:
                raise
            except ClientError as exc:
                if not self.client.connected:
                    raise
                self._drop(f"frame refused: {exc}")
                await asyncio.sleep(self.governor.interval)
                continue
            now = self.clock()
            repeats = self.stats.repeats
            self.take(reply.payload, now - started)
            interval = self.governor.interval
            if self.stats.repeats > repeats:
                # The server's camera had nothing newer yet (a forwarder polls it ~10 times a second):
                # ask again after a quarter of the interval, not a whole one, so frames are not late.
                interval /= 4
            wait = started + interval - self.clock()
            if end is not None:
                wait = min(wait, end - self.clock())
            if wait > 0:
                await asyncio.sleep(wait)

    def take(self, payload: bytes, round_trip: float) -> LiveFrame | None:
        """One reply payload: checked, timed, handed on when new; None when dropped or a repeat."""
        now = self.clock()
        received = self.wall_ns()
        try:
            frame, stamp = parse_frame(payload)
        except BadFrame as exc:
            self._drop(str(exc))
            self.governor.observe(now, round_trip, None)
            return None
        age = None if stamp is None else max(received - stamp, 0) / 1e9
        jpeg = bytes(frame.jpeg)
        key = (stamp, len(jpeg), zlib.crc32(jpeg))
        if self._last == key:
            # The same picture again (a still robot, a camera polled slower than we ask): its age says
            # how long nothing changed, not how late the link is — only the round trip is judged.
            self.governor.observe(now, round_trip, None)
            self.stats.repeats += 1
            self._report()
            return None
        self.governor.observe(now, round_trip, age)
        self._last = key
        self._sequence += 1
        self.stats.add(now, len(jpeg), None if age is None else age * 1000.0)
        live = LiveFrame(
            jpeg, frame.width, frame.height, self.source, self._sequence, received, stamp, round_trip
        )
        self.on_frame(live)
        self._report()
        return live

    def _drop(self, why: str) -> None:
        self.stats.dropped += 1
        self.note = why
        self._report()

    def status(self) -> VideoStatus:
        fps, kbps = self.stats.rates(self.clock())
        return VideoStatus(
            fps=fps,
            kbps=kbps,
            age_ms=self.stats.last_age_ms,
            target_fps=self.governor.target_fps,
            rate_fps=self.governor.rate_fps,
            backoff=self.governor.reason,
            paused=self.paused,
            dropped=self.stats.dropped,
            note=self.note,
        )

    def _report(self) -> None:
        if self.on_status is not None:
            self.on_status(self.status())

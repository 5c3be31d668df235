"""Live video: one picture request in flight at a time, the next sent when a frame arrives.

ARIA offers no video stream, only a picture per request (``getPicture<Name>``,
else ``sendVideo``), so "video" is a loop on the network thread: ask, wait for
the frame, hand it on, ask again — never more than one request in flight, and
no sooner than the frame-rate setting allows. A camera (ARIA's video forwarder polls its
own about ten times a second) answers a request made before its next picture with the
last one again; :class:`FramePacer` learns the camera's period from those repeats and asks
when the next picture should be ready, so requests follow new frames (not the frame-rate
setting) and their age stays low. The loop only checks a frame's
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
import time
import zlib
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

from ..base.i18n import N_, Said
from ..base.units import Quantity
from ..protocol.errors import ProtocolError
from ..protocol.payloads.camera import VideoFrame
from ..values.intents import picture_source
from ..values.state import VideoStatus
from .connection import AriaClient
from .defaults import MAX_FPS, MIN_FPS
from .errors import ClientError, ClientTimeout, NotSupported, ServerClosed
from .jpeg_bounds import MAX_SIDE, STAMP_PREFIX, fill_problem, read_header

__all__ = ["MAX_SIDE", "STAMP_PREFIX", "BadFrame", "VideoFeed", "check_frame", "frame_stamp", "parse_frame"]
DEFAULT_FPS = 15.0
DEFAULT_QUALITY: int | None = None
"""None: leave the quality argument out (the server's own choice), as ARIA's example client does."""
RTT_LIMIT_S = 0.5
AGE_LIMIT_S = 1.0
RECOVER_AFTER_S = 3.0
REQUEST_TIMEOUT_S = 5.0
CONSUMER_WAIT_S = 1.0
"""Longest the loop waits for the consumer to show a frame before asking for the next anyway."""
PERIOD_SAMPLES = 9
"""Periods measured between repeats the pacer keeps; their median is the camera's period."""
MARGIN_S = 0.003
"""A request for a new frame goes this long after the moment the frame is expected, at least."""
DRIFT_S = 0.00025
"""Each new frame got as aimed moves the expected moment this much earlier: after about
``margin / DRIFT_S`` frames a request comes too soon, and the repeat it gets pins the moment down
again — about one repeat in twelve frames, so a camera whose clock wanders is followed (a repeat every
eight frames, with half a millisecond, cost about 1.2 requests a new picture against a real server)."""
PATIENCE = 16
"""New frames got as aimed in a row after which the drift doubles with each further one: a period
learned a little long must not leave the requests later and later (no repeat would say so)."""
AIMED_WINDOW = 20
"""Aimed requests over which the share of repeats is watched: above :data:`REPEATS_HIGH` the margin
widens by :data:`MARGIN_STEP_S` (a server whose clock ticks coarsely, a loaded machine), below
:data:`REPEATS_LOW` it narrows by a quarter of that, down to :data:`MARGIN_S`."""
REPEATS_HIGH = 0.1
REPEATS_LOW = 0.05
MARGIN_STEP_S = 0.001
RETRY_MIN_S = 0.003
"""After a repeat, ask again this soon, then :data:`RETRY_GROWTH` times longer after each further
repeat, up to :data:`RETRY_MAX_S`: a camera that makes no new pictures is asked about once a second.
A frame a few ms late is still pinned down closely (3, 4.5, 6.8 ms…); one held up for tens of ms (a
loaded robot computer: the benchmark's simulator at load 6 shows such stalls of 10-40 ms) costs a
few requests, not one every 3 ms — at the price of fetching that one frame up to about half its delay
later. ``bench_videopace``, six rounds each, turn about, medians: 1.20 requests per new frame at
--fps 15 and 1.21 at 30, against 1.28 and 1.23 with eight 3 ms retries first; frame age p50 and p95
no higher."""
RETRY_GROWTH = 1.5
QUICK_RETRIES = 1
"""Retries at :data:`RETRY_MIN_S` before they grow (more while the period is only roughly known)."""
PRECISE_S = 0.004
"""Two moments pinned down this closely together (their errors summed: half the time from each
repeat to its new frame, so quick retries on both sides) measure the period; looser ones give a
rough period that only says when to look next."""
RETRY_MAX_S = 1.0
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
        slow: Said | None = None
        if rtt > self.rtt_limit:
            slow = Said(N_("round trip {time}"), time=Quantity(rtt * 1000, "ms"))
        elif age is not None and age > self.age_limit:
            slow = Said(N_("frames {time} old"), time=Quantity(age * 1000, "ms"))
        if slow:
            self._healthy_since = None
            if self.factor < 32 and self.rate_fps / 2 >= MIN_FPS / 2:
                self.factor *= 2
            self.reason = Said(
                N_("slowed to {rate}: {why}"), rate=Quantity(self.rate_fps, "fps", 1), why=slow
            )
            return
        if self.factor == 1:
            self.reason = ""
            return
        if self._healthy_since is None:
            self._healthy_since = now
        elif now - self._healthy_since >= RECOVER_AFTER_S:
            self.factor //= 2
            self._healthy_since = now
            self.reason = (
                ""
                if self.factor == 1
                else Said(N_("recovering: {rate}"), rate=Quantity(self.rate_fps, "fps", 1))
            )

    def set_fps(self, fps: float) -> None:
        self.target_fps = clamp_fps(fps)


def clamp_fps(fps: float) -> float:
    return min(max(float(fps), MIN_FPS), MAX_FPS)


class FramePacer:
    """When to ask for the next picture: never sooner than the frame-rate setting allows, and never
    sooner than the camera makes a new picture (its period learned from the repeats it answers).

    ``after(sent, outcome, min_interval)`` takes the send time of the request just answered, what it
    brought (``"new"``, ``"repeat"`` or ``"none"``: dropped, refused, timed out) and the shortest
    interval the rate governor allows between frames; it returns when to send the next request.

    A new frame was ready when its request went out; a repeat means the next one was not ready yet.
    A repeat followed by a new frame brackets the moment it became ready (:attr:`ready_at`); from one
    such moment to the next, over the frames between, comes the camera's :attr:`period` (median of
    recent ones). The pacer then asks :attr:`margin` after each frame should be ready, drifting
    earlier until a repeat pins the moment down again. Until it knows a period it asks at the
    frame-rate setting; a camera faster than the setting fills every request and never repeats.
    """

    def __init__(self) -> None:
        self.period: float | None = None
        """The camera's period as learned (s); None until two repeats bracketed frames."""
        self.ready_at: float | None = None
        """When the newest frame is thought to have become ready (the clock of ``sent``)."""
        self.margin = MARGIN_S
        """How long after a frame's expected moment it is asked for (see :data:`AIMED_WINDOW`)."""
        self._aimed: deque[bool] = deque(maxlen=AIMED_WINDOW)
        self._rough: deque[tuple[float, float]] = deque(maxlen=3)
        """Rough measures of the period (and give or take how much) since the last precise one."""
        """Whether each recent aimed request got a repeat."""
        self.requests = 0
        self.new_frames = 0
        self._periods: deque[float] = deque(maxlen=PERIOD_SAMPLES)
        self._too_soon: float | None = None
        """Send time of the last repeat since the newest frame: the next one came after it."""
        self._bracketed: tuple[float, float] | None = None
        """The last moment a repeat pinned down (and give or take how much), and the frames counted
        since (:attr:`_since`)."""
        self._slack = 0.0
        """How far off :attr:`period` may be while only rough measures made it."""
        self._quick = QUICK_RETRIES
        """Repeats answered by a quick retry before the retries slow down."""
        self._since = 0
        self._misses = 0
        self._expected: float | None = None
        """When the request just answered was aimed at a frame being ready (None: not aimed)."""

    def after(self, sent: float, outcome: str, min_interval: float) -> float:
        self.requests += 1
        if outcome == "new":
            return self._new(sent, min_interval)
        if outcome == "repeat":
            return self._repeat(sent, min_interval)
        return sent + min_interval

    def _new(self, sent: float, min_interval: float) -> float:
        self.new_frames += 1
        self._since += 1
        if self._too_soon is not None:
            ready = (self._too_soon + sent) / 2  # became ready between the repeat and this request
            self._learn(ready, (sent - self._too_soon) / 2)
        elif self._expected is not None and sent <= self._expected + self.margin:
            drift = DRIFT_S * 2 ** max(0, self._since - PATIENCE)
            if self.period is not None:
                drift = min(drift, self.period / 4)
            ready = self._expected - self.margin - drift  # ready by then, maybe sooner: look earlier
            self._aimed_outcome(False)
        else:
            ready = sent - self.margin  # asked late (paced by the setting, or held up): ready by now
        self.ready_at, self._too_soon, self._misses = ready, None, 0
        if self.period is None or self.period <= min_interval:
            self._expected = None  # no period yet, or a camera faster than we ask: the setting paces
            return sent + min_interval
        expected = ready + self.period + self.margin - 2 * self._slack  # a rough period: look early
        self._quick = QUICK_RETRIES + round(4 * self._slack / RETRY_MIN_S)  # …and through its doubt
        self._expected = expected if expected >= sent + min_interval else None
        return max(expected, sent + min_interval)

    def _aimed_outcome(self, repeat: bool) -> None:
        """Keep about one aimed request in eight a repeat, whatever the server's timing."""
        self._aimed.append(repeat)
        if len(self._aimed) < AIMED_WINDOW // 2:
            return
        share = sum(self._aimed) / len(self._aimed)
        if share > REPEATS_HIGH and self.period is not None:
            self.margin = min(self.margin + MARGIN_STEP_S, self.period / 4)
            self._aimed.clear()
        elif share < REPEATS_LOW:
            self.margin = max(MARGIN_S, self.margin - MARGIN_STEP_S / 4)

    def _learn(self, ready: float, error: float) -> None:
        """A moment pinned down by a repeat (give or take ``error``): with the one before, a
        measure of the period — kept when precise; rough ones serve until a precise one comes,
        and three rough ones that disagree with the period say the camera changed its pace."""
        before, frames = self._bracketed, self._since
        self._bracketed, self._since = (ready, error), 0
        if before is None or ready <= before[0]:
            return
        sample, slack = (ready - before[0]) / frames, (error + before[1]) / frames
        import statistics  # here, not at the top: the window's launch skips it (and fractions, decimal)

        if slack <= PRECISE_S:
            self._periods.append(sample)
            self._rough.clear()
            self.period, self._slack = statistics.median(self._periods), 0.0
            return
        self._rough.append((sample, slack))
        rough = statistics.median(r for r, _ in self._rough)
        if self.period is None or (len(self._rough) >= 3 and abs(rough - self.period) > self.period / 4):
            self._periods.clear()
            self.period, self._slack = rough, max(sl for _, sl in self._rough)

    def _repeat(self, sent: float, min_interval: float) -> float:
        if self._expected is not None:  # aimed, yet too soon
            self._aimed_outcome(True)
        self._misses += 1
        self._too_soon = sent
        self._expected = None
        retry = RETRY_MIN_S * RETRY_GROWTH ** max(0, self._misses - self._quick)
        return sent + min(retry, max(RETRY_MAX_S, min_interval))


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
        import statistics

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
        self.pacer = FramePacer()

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
                self.pacer.after(started, "none", self.governor.interval)
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
            live = self.take(reply.payload, now - started)
            outcome = "new" if live is not None else "repeat" if self.stats.repeats > repeats else "none"
            wait = self.pacer.after(started, outcome, self.governor.interval) - self.clock()
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

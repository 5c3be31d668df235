"""Replay a recording through the live client code: the clock, the paced link and the feeder (GTK-free).

:class:`ReplayClock` maps recording time to the wall clock (play, pause, speed x0.25–x8,
seek). :class:`PacedLink` is the :class:`~rtmu.client.link.Link` a session reads from:
it hands out each recorded server chunk once the clock has reached its time *and* the
client has written as many counted packets as it had live (see
:mod:`.replay_file`); it sends nothing anywhere and refuses drive packets outright.
:class:`Replayer` is the opener the session's runner uses, plus the camera pictures.

Seeking forward just moves the clock: the link releases what is due as fast as the
client takes it. Seeking backward rebuilds: a new connection replays from the start
to the target as fast as it can (measured in ``bench/bench_replay.py``), which keeps
every part of the state exactly as the live session built it — snapshots would have to
copy the session's internals and would drift from them.
"""

from __future__ import annotations

import asyncio
import contextlib
import threading
import time
from collections.abc import Callable

from ..client.link import Link, RecordedLink
from ..client.roles import Role
from ..client.session import SessionConfig
from ..protocol.decoder import PacketDecoder
from ..values.state import CameraChanged, CameraImage, StateChange
from .replay_file import RecordedConnection

REPLAY_CONFIG = SessionConfig(
    ping_interval=3600.0, lost_after=3600.0, connect_timeout=3600.0, role=Role.OBSERVER
)
"""A replaying session: no live link to watch (no pings, no staleness by wall clock, no guardian), and
an observer — its client cannot put a motion request on any link, the replay's included."""

SPEEDS = (0.25, 0.5, 1.0, 2.0, 4.0, 8.0)
POLL = 0.05
"""Longest sleep of a waiting link: pause, speed and seeks take effect within it."""
GATE_GRACE = 0.3
"""Real seconds a due chunk waits for a client packet the replay does not send before it goes anyway."""
REPLAY_HOST = "replay"


class ReplayClock:
    """Recording time (ns since the epoch, as logged) as a function of the wall clock. Thread-safe."""

    def __init__(self, start_ns: int, end_ns: int, clock: Callable[[], float] = time.monotonic) -> None:
        self.start_ns = start_ns
        self.end_ns = max(end_ns, start_ns)
        self._clock = clock
        self._lock = threading.Lock()
        self._at_ns = start_ns
        self._wall = clock()
        self._speed = 1.0
        self._playing = False
        self.generation = 0
        """Bumped by every seek and every play/pause/speed change (waiters re-read the clock)."""

    @property
    def speed(self) -> float:
        return self._speed

    @property
    def playing(self) -> bool:
        return self._playing

    def seconds(self) -> float:
        """The replay's clock for a session: time stands still while paused, so nothing goes stale."""
        return self.now_ns() / 1e9

    def now_ns(self) -> int:
        with self._lock:
            return self._now()

    def _now(self) -> int:
        if not self._playing:
            return self._at_ns
        ahead = (self._clock() - self._wall) * self._speed * 1e9
        return min(self.end_ns, self._at_ns + round(ahead))

    def _rebase(self) -> None:
        self._at_ns = self._now()
        self._wall = self._clock()
        self.generation += 1

    def play(self) -> None:
        with self._lock:
            self._rebase()
            self._playing = True

    def pause(self) -> None:
        with self._lock:
            self._rebase()
            self._playing = False

    def set_speed(self, speed: float) -> None:
        if not SPEEDS[0] <= speed <= SPEEDS[-1]:
            raise ValueError(f"replay speed must be between x{SPEEDS[0]} and x{SPEEDS[-1]}")
        with self._lock:
            self._rebase()
            self._speed = speed

    def seek(self, at_ns: int) -> None:
        with self._lock:
            self._rebase()
            self._at_ns = min(max(at_ns, self.start_ns), self.end_ns)

    def due_in(self, at_ns: int) -> float | None:
        """Real seconds until the clock reaches ``at_ns`` (0 if it has; None while paused before it)."""
        with self._lock:
            now = self._now()
            if now >= at_ns:
                return 0.0
            if not self._playing:
                return None
            return (at_ns - now) / 1e9 / self._speed

    @property
    def finished(self) -> bool:
        return self.now_ns() >= self.end_ns


class PacedLink(RecordedLink):
    """A :class:`Link` over one recorded connection, paced by a :class:`ReplayClock`."""

    def __init__(self, recorded: RecordedConnection, clock: ReplayClock) -> None:
        super().__init__()
        self.recorded = recorded
        self.clock = clock
        self.position = 0
        """Server chunks handed to the client so far."""
        self.counted = 0
        """Counted client packets written so far (compared with each chunk's gate)."""
        self.refused = 0
        """Drive packets the client tried to send (none ever leave)."""
        self.fallbacks = 0
        """Chunks that went on after :data:`GATE_GRACE` without the client packet they waited for."""
        self.written = 0
        self.delivered_ns = recorded.start_ns
        """Recording time of the last chunk handed out."""
        self._slack = 0
        self._decoder = PacketDecoder()

    @property
    def exhausted(self) -> bool:
        return self.position >= len(self.recorded.chunks)

    async def read(self, max_bytes: int) -> bytes:
        while not self._closed:
            if self.exhausted:
                await self._wait(POLL)  # open and silent after the end, as a quiet server
                continue
            chunk = self.recorded.chunks[self.position]
            due = self.clock.due_in(chunk.at_ns)
            if due != 0.0:
                await self._wait(POLL if due is None else min(due, POLL))
                continue
            if self.counted + self._slack < chunk.gate and not await self._gate(chunk.gate):
                self._slack = chunk.gate - self.counted  # a packet we do not send: go on without it
                self.fallbacks += 1
            self.position += 1
            self.delivered_ns = chunk.at_ns
            await asyncio.sleep(0)  # let the client's tasks run between reads, as time did live
            return chunk.data
        return b""

    async def _gate(self, gate: int) -> bool:
        """Wait (bounded) until the client has written up to ``gate``; False when it did not."""
        deadline = time.monotonic() + GATE_GRACE
        while self.counted + self._slack < gate:
            left = deadline - time.monotonic()
            if left <= 0 or self._closed:
                return False
            await self._wait(left)
        return True

    async def _wait(self, seconds: float) -> None:
        self._changed.clear()
        with contextlib.suppress(TimeoutError):
            await asyncio.wait_for(self._changed.wait(), seconds)

    def write(self, data: bytes) -> None:
        """Counted, never sent; drive packets are refused (counted in :attr:`refused`)."""
        self.written += len(data)
        for packet in self._decoder.feed(data):
            if packet.command in self.recorded.motion:
                self.refused += 1
            elif packet.command not in self.recorded.uncounted:
                self.counted += 1
        self._changed.set()


class Replayer:
    """The opener of a replaying session's runner, and the camera pictures beside it.

    ``publish`` (network thread) gets each recorded camera picture as a ``CameraChanged``
    when the clock passes its time. Every call of :meth:`open` starts the recording from
    its beginning (a backward seek reconnects).
    """

    def __init__(
        self,
        recorded: RecordedConnection,
        clock: ReplayClock | None = None,
        publish: Callable[[StateChange], None] | None = None,
    ) -> None:
        self.recorded = recorded
        self.clock = clock or ReplayClock(recorded.start_ns, recorded.end_ns)
        self.publish = publish
        self.link: PacedLink | None = None
        self.opened = 0
        self._pictures: asyncio.Task[None] | None = None

    async def open(self, host: str, port: int) -> Link:
        if self.link is not None:
            self.link.close()
        if self._pictures is not None:
            self._pictures.cancel()
        self.opened += 1
        link = self.link = PacedLink(self.recorded, self.clock)
        if self.publish is not None and self.recorded.images:
            self._pictures = asyncio.get_running_loop().create_task(self._show_pictures(link))
        return link

    async def _show_pictures(self, link: PacedLink) -> None:
        """Each picture once the link has delivered the bytes up to its time (only the latest when behind)."""
        images = self.recorded.images
        index = 0
        sequence = 0
        while index < len(images) and not link.is_closing():
            at = images[index][0]
            if self.clock.now_ns() < at or link.delivered_ns < at:
                await asyncio.sleep(POLL)
                continue
            while index + 1 < len(images) and images[index + 1][0] <= min(
                self.clock.now_ns(), link.delivered_ns
            ):
                index += 1  # behind after a seek: only the latest picture matters
            sequence += 1
            jpeg = images[index][1]
            size = _jpeg_size(jpeg)
            if size is not None and self.publish is not None:
                image = CameraImage(
                    jpeg=jpeg, width=size[0], height=size[1], source="recording",
                    received_at=time.monotonic(), sequence=sequence,
                )  # fmt: skip
                self.publish(CameraChanged(image))
            index += 1

    def status_age(self) -> float | None:
        """Seconds of *recording* time since the last server bytes shown: a paused replay is not stale,
        a gap the live link had is, a replay catching up with its clock after a seek is not (the
        window's staleness checks use this instead of the wall clock)."""
        link = self.link
        if link is None or link.position == 0:
            return None
        now = self.clock.now_ns()
        if not link.exhausted and link.recorded.chunks[link.position].at_ns <= now:
            # Behind the clock (the rebuild after a seek back, a busy thread): the recorded bytes are
            # being handed over as fast as they are read; the recording had no gap here.
            return 0.0
        return max(0.0, (now - link.delivered_ns) / 1e9)

    def seek_needs_rebuild(self, at_ns: int) -> bool:
        """A seek to before what the current link has delivered has to start again from the beginning."""
        link = self.link
        return link is not None and at_ns < link.delivered_ns


def _jpeg_size(jpeg: bytes) -> tuple[int, int] | None:
    """(width, height) from a JPEG's SOF marker, without decoding it; None when there is none."""
    pos = 2
    end = len(jpeg)
    if jpeg[:2] != b"\xff\xd8":
        return None
    while pos + 9 <= end:
        if jpeg[pos] != 0xFF:
            return None
        marker = jpeg[pos + 1]
        length = int.from_bytes(jpeg[pos + 2 : pos + 4], "big")
        if 0xC0 <= marker <= 0xCF and marker not in (0xC4, 0xC8, 0xCC):
            height = int.from_bytes(jpeg[pos + 5 : pos + 7], "big")
            width = int.from_bytes(jpeg[pos + 7 : pos + 9], "big")
            return (width, height) if width and height else None
        pos += 2 + length
    return None

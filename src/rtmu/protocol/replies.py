"""Which reply answers which request, and where it ends — sans-I/O (protocol §3.7, §4.5).

Replies carry no request id in ArNetworking: a reply is matched to the oldest
pending request of the same data number (ARIA answers in order), and each data
has its own end pattern (one packet, n packets, a zero-length packet, a map's
end marker). :class:`ReplyTracker` owns a tracked request from the moment it is
sent until its reply ends, fails, or is given up, and turns every data packet
into events (``DataReceived`` when no request claims it, else ``ReplyPacket``
then, at the end, ``ReplyComplete`` or ``ReplyFailed``).

A request whose waiter gave up (timeout, cancel) is *abandoned*: its slot stays,
so a late reply still lines up with it and cannot be taken for the next
request's. But a reply that never comes must not shift every later reply by one
for good, so an abandoned slot that has received nothing is dropped as soon as
a newer request of the same data is sent (a reply later than its requester's
whole timeout is treated as lost), and any abandoned slot is dropped after
``abandon_grace`` s without a packet (a map that stalled half way). At most
``max_pending`` requests per data number wait at once.

No clock of its own: every call that needs the time is given ``now``.
"""

from __future__ import annotations

import itertools
from collections import deque
from collections.abc import Callable, Iterator

from .errors import MapTooLarge, ProtocolError
from .events import DataReceived, Event, ReplyComplete, ReplyError, ReplyFailed, ReplyId, ReplyPacket

_new_tuple = tuple.__new__
"""Builds the per-packet named-tuple events without their Python ``__new__`` frame."""

MAX_REPLY_PACKETS = 1_000_000
"""Default bound on the packets of one collected reply, or of a streamed one's unread packets."""
MAX_REPLY_BYTES = 64 << 20
"""Default bound on the payload bytes of one collected reply, or of a streamed one's unread packets."""
ABANDON_GRACE = 0.5
"""Seconds an abandoned request's slot waits quietly for a late reply before the reply counts as lost."""
MAX_PENDING_PER_DATA = 64
"""Requests of one data number that may wait for replies at once (abandoned slots included)."""


# -- how a reply ends -----------------------------------------------------------------------------
# ArNetworking has no end-of-reply framing; each data has its own pattern.


class EndRule:
    """Decides, packet by packet, whether a reply is complete."""

    def done(self, payload: bytes, count_before: int) -> bool:
        raise NotImplementedError


class Single(EndRule):
    """Exactly ``n`` packets (1 for most data; ``getSensorCurrent`` with n names)."""

    def __init__(self, n: int = 1) -> None:
        self.n = n

    def done(self, payload: bytes, count_before: int) -> bool:
        return count_before + 1 >= self.n


class UntilEmpty(EndRule):
    """RETURN_UNTIL_EMPTY: a zero-length packet ends the series."""

    def done(self, payload: bytes, count_before: int) -> bool:
        return not payload


class Until(EndRule):
    """The caller's own end test (a map assembler's ``feed``); a ``ProtocolError`` from it fails the reply."""

    def __init__(self, until: Callable[[bytes], bool]) -> None:
        self.until = until

    def done(self, payload: bytes, count_before: int) -> bool:
        return self.until(payload)


class MapStream(EndRule):
    """``getMap``/``getMapBinary``: ends with a zero-length packet, or at once with one ``00`` (no map)."""

    def done(self, payload: bytes, count_before: int) -> bool:
        return not payload or (count_before == 0 and payload == b"\x00")


MAP_STREAMS = frozenset({"getMap", "getMapBinary", "getMapMultiScans", "getMapWithMaxCategory"})


def end_rule(
    flags: frozenset[str], name: str, expect: int | None = None, until: Callable[[bytes], bool] | None = None
) -> EndRule | None:
    """Where the reply to ``name`` ends; None = the data has no reply (RETURN_NONE)."""
    if until is not None:
        return Until(until)
    if expect is not None:
        return Single(expect)
    if name in MAP_STREAMS:
        return MapStream()
    if name == "popupList" or "RETURN_UNTIL_EMPTY" in flags:
        return UntilEmpty()
    if "RETURN_NONE" in flags:
        return None
    return Single()


class TooManyPending(ProtocolError):
    """``max_pending`` requests of this data already wait for replies: the caller must not send more."""

    def __init__(self, name: str, count: int) -> None:
        super().__init__(f"{count} requests for {name!r} are already waiting to be answered")
        self.name = name
        self.count = count


# -- one pending request --------------------------------------------------------------------------


class PendingReply:
    """One request waiting for its reply packets (one slot in its data number's queue).

    What it holds is bounded: a collected reply by ``max_packets``/``max_bytes`` in all, a
    streamed one by the packets/bytes its reader has not taken yet (a streamed reply keeps
    no payloads: each is handed out in a ``ReplyPacket``). Past a bound the reply fails
    with ``TOO_LARGE`` and the slot, abandoned, swallows the rest of the reply.
    """

    __slots__ = (
        "_until",
        "abandoned_at",
        "count",
        "fallback",
        "held_bytes",
        "held_packets",
        "id",
        "last_activity",
        "max_bytes",
        "max_packets",
        "payloads",
        "rule",
        "streaming",
    )

    def __init__(
        self,
        reply: ReplyId,
        rule: EndRule,
        fallback: EndRule,
        *,
        streaming: bool,
        max_packets: int,
        max_bytes: int,
    ) -> None:
        self.id = reply
        self.rule = rule
        self._until = rule.until if isinstance(rule, Until) else None
        """The caller's own end test, called directly (a map's million packets skip one frame each)."""
        self.fallback = fallback
        """Where the reply ends without the caller's own test (used once the caller is gone)."""
        self.streaming = streaming
        self.max_packets = max_packets
        self.max_bytes = max_bytes
        self.payloads: list[bytes] = []
        self.count = 0
        self.held_packets = 0
        self.held_bytes = 0
        self.abandoned_at: float | None = None
        self.last_activity = 0.0

    @property
    def abandoned(self) -> bool:
        return self.abandoned_at is not None

    def feed(self, payload: bytes, now: float) -> tuple[bool, ReplyComplete | ReplyFailed | None]:
        """One packet of this reply → (the slot is done, the outcome to report if any)."""
        if self.abandoned_at is not None:
            return self._swallow(payload, now), None
        try:
            test = self._until
            finished = test(payload) if test is not None else self.rule.done(payload, self.count)
        except MapTooLarge as exc:  # more than any map can be: an endless or hostile stream
            return True, self._failed(
                ReplyError.MALFORMED, f"the server's map is too large, download stopped: {exc}"
            )
        except ProtocolError as exc:  # the caller's end test found the reply malformed
            return True, self._failed(ReplyError.MALFORMED, f"malformed reply: {exc}")
        self.count += 1
        self.held_packets += 1
        self.held_bytes += len(payload)
        if not self.streaming:
            self.payloads.append(payload)
        if finished:
            payloads, self.payloads = tuple(self.payloads), []
            return True, ReplyComplete(self.id, payloads)
        if self.held_packets > self.max_packets or self.held_bytes > self.max_bytes:
            return False, self._overflow(self.held_packets > self.max_packets, now)
        return False, None

    def taken(self, payload: bytes) -> None:
        """A stream's reader took ``payload``: it is no longer held for it."""
        self.held_packets -= 1
        self.held_bytes -= len(payload)

    def abandon(self, now: float) -> None:
        """The waiter is gone: keep the slot so the rest of the reply lines up, but keep nothing."""
        self.abandoned_at = self.last_activity = now
        self.payloads = []
        self.held_packets = self.held_bytes = 0

    def expired(self, now: float, grace: float) -> bool:
        return self.abandoned_at is not None and now - self.last_activity >= grace

    def _overflow(self, by_count: bool, now: float) -> ReplyFailed:
        limit = f"{self.max_packets} packets" if by_count else f"{self.max_bytes} bytes"
        waiting = "not read yet" if self.streaming else "in one reply"
        self.abandon(now)
        return self._failed(
            ReplyError.TOO_LARGE, f"more than {limit} of {self.id.name!r} {waiting}; the rest is dropped"
        )

    def _failed(self, reason: ReplyError, message: str) -> ReplyFailed:
        self.payloads = []
        return ReplyFailed(self.id, reason, message)

    def _swallow(self, payload: bytes, now: float) -> bool:
        self.last_activity = now
        try:
            done = self.fallback.done(payload, self.count)
        except ProtocolError:
            done = True
        self.count += 1
        return done


# -- all pending requests of one connection --------------------------------------------------------


class ReplyTracker:
    """The pending requests of one connection, a queue per data number; see the module notes."""

    def __init__(
        self, *, abandon_grace: float = ABANDON_GRACE, max_pending: int = MAX_PENDING_PER_DATA
    ) -> None:
        self.abandon_grace = abandon_grace
        self.max_pending = max_pending
        self._queues: dict[int, deque[PendingReply]] = {}
        self._serials = itertools.count(1)
        self.now = 0.0
        """The latest time given (``feed`` without ``now`` uses it: time does not move on its own)."""

    def expect(
        self,
        number: int,
        name: str,
        rule: EndRule,
        fallback: EndRule,
        *,
        now: float,
        streaming: bool = False,
        max_packets: int = MAX_REPLY_PACKETS,
        max_bytes: int = MAX_REPLY_BYTES,
    ) -> PendingReply:
        """Register a request about to be sent; raises :class:`TooManyPending` (nothing registered)."""
        self.now = now
        queue = self._queues.setdefault(number, deque())
        self._expire(queue, now, newer_request=True)
        while len(queue) >= self.max_pending and queue[0].abandoned_at is not None:
            queue.popleft()  # make room: the oldest abandoned slot goes first
        if len(queue) >= self.max_pending:
            raise TooManyPending(name, len(queue))
        reply = ReplyId(next(self._serials), number, name)
        pending = PendingReply(
            reply, rule, fallback, streaming=streaming, max_packets=max_packets, max_bytes=max_bytes
        )
        queue.append(pending)
        return pending

    def feed(self, number: int, name: str | None, payload: bytes, now: float | None = None) -> list[Event]:
        """One data packet → ``[DataReceived]``, or ``[ReplyPacket]`` plus the reply's outcome if it ended."""
        if now is None:
            now = self.now
        self.now = now
        queue = self._queues.get(number)
        if queue and queue[0].abandoned_at is not None:
            self._expire(queue, now)
        if not queue:
            return [_new_tuple(DataReceived, (number, name, payload))]
        head = queue[0]
        was_abandoned = head.abandoned_at is not None
        done, outcome = head.feed(payload, now)
        if done:
            queue.popleft()
        if outcome is None:  # one more packet of a reply that goes on: the hot path
            return [_new_tuple(ReplyPacket, (head.id, payload, was_abandoned))]
        refused = isinstance(outcome, ReplyFailed) and outcome.reason is ReplyError.MALFORMED
        return [ReplyPacket(head.id, payload, swallowed=was_abandoned or refused), outcome]

    def abandon(self, reply: ReplyId, now: float) -> None:
        """The waiter gave up (timeout, cancel, a stream closed early); no-op if the reply is over."""
        pending = self.get(reply)
        if pending is not None and pending.abandoned_at is None:
            pending.abandon(now)

    def taken(self, reply: ReplyId, payload: bytes) -> None:
        """A stream's reader took one payload (see :meth:`PendingReply.taken`)."""
        pending = self.get(reply)
        if pending is not None and pending.abandoned_at is None:
            pending.taken(payload)

    def get(self, reply: ReplyId) -> PendingReply | None:
        """The slot still waiting for ``reply``, or None once it ended or was dropped."""
        for pending in self._queues.get(reply.number, ()):
            if pending.id is reply:
                return pending
        return None

    def waiting(self, number: int) -> tuple[PendingReply, ...]:
        return tuple(self._queues.get(number, ()))

    def __iter__(self) -> Iterator[PendingReply]:
        for queue in self._queues.values():
            yield from queue

    def clear(self) -> list[ReplyId]:
        """Forget every pending request (the connection is over); returns those whose waiters remain."""
        live = [p.id for p in self if p.abandoned_at is None]
        self._queues.clear()
        return live

    def _expire(self, queue: deque[PendingReply], now: float, *, newer_request: bool = False) -> None:
        """Drop abandoned slots at the head whose replies count as lost (see the module notes)."""
        while queue:
            head = queue[0]
            if head.abandoned_at is None:
                return
            if not (head.expired(now, self.abandon_grace) or (newer_request and head.count == 0)):
                return
            queue.popleft()

"""Put each direction of each TCP connection back in sequence order.

Handles retransmissions and overlaps (old bytes are trimmed, counted once),
out-of-order segments (held until the hole fills), SYN/FIN/RST, a port pair
reused by a new connection, and a capture that starts mid-stream (the first
segment seen sets the starting sequence number). A hole that never fills
becomes a :class:`StreamGap` once too much data waits behind it, or at the end.
"""

from __future__ import annotations

import heapq
from collections import OrderedDict

from .base import CaptureEvent, CaptureStats, Endpoint, Flow, StreamData, StreamEnd, StreamGap
from .net import ACK, FIN, RST, SYN, Segment

MAX_CLOSED = 4096
MAX_PENDING_BYTES = 8 << 20
"""Out-of-order data held per direction before the hole in front of it is declared lost."""


def _delta(seq: int, ref: int) -> int:
    """Signed distance from ``ref`` to ``seq`` in 32-bit sequence space."""
    d = (seq - ref) & 0xFFFFFFFF
    return d - 0x100000000 if d & 0x80000000 else d


class _Direction:
    __slots__ = (
        "ended",
        "fin_seq",
        "next_seq",
        "order",
        "pending",
        "pending_bytes",
        "position",
        "started",
        "syn_seq",
    )

    def __init__(self) -> None:
        self.next_seq: int | None = None
        """The next sequence number expected (32-bit, wraps)."""
        self.position = 0
        """Bytes of the stream accounted for so far (delivered or reported missing); never wraps."""
        self.syn_seq: int | None = None
        self.fin_seq: int | None = None
        self.pending: dict[int, tuple[bytes, int]] = {}
        """Out-of-order segments by stream position: (captured bytes, bytes cut by the snap length)."""
        self.order: list[int] = []
        """A heap of the positions in ``pending``."""
        self.pending_bytes = 0
        self.started = False
        self.ended = False


class _Connection:
    __slots__ = ("directions", "flow")

    def __init__(self, flow: Flow) -> None:
        self.flow = flow
        self.directions = {flow.first: _Direction(), flow.second: _Direction()}


class TcpReassembler:
    """Feed segments in capture order with :meth:`segment`; call :meth:`finish` at the end."""

    def __init__(self, stats: CaptureStats, first_flow_id: int = 1) -> None:
        self._stats = stats
        self._connections: dict[tuple[Endpoint, Endpoint], _Connection] = {}
        self._closed: OrderedDict[tuple[Endpoint, Endpoint], _Connection] = OrderedDict()
        """Recently finished connections: late retransmissions land here, not in a new connection."""
        self._next_id = first_flow_id

    def _key(self, a: Endpoint, b: Endpoint) -> tuple[Endpoint, Endpoint]:
        return (a, b) if a <= b else (b, a)

    def _new(self, src: Endpoint, dst: Endpoint) -> _Connection:
        conn = _Connection(Flow(self._next_id, "tcp", src, dst))
        self._next_id += 1
        key = self._key(src, dst)
        self._connections[key] = conn
        self._closed.pop(key, None)
        return conn

    def _retire(self, key: tuple[Endpoint, Endpoint], conn: _Connection) -> None:
        """Both directions ended: keep only a bounded memory of the connection."""
        if self._connections.get(key) is conn:
            del self._connections[key]
            self._closed[key] = conn
            if len(self._closed) > MAX_CLOSED:
                self._closed.popitem(last=False)

    def segment(self, seg: Segment, time: float | None) -> list[CaptureEvent]:
        events: list[CaptureEvent] = []
        key = self._key(seg.src, seg.dst)
        conn = self._connections.get(key) or self._closed.get(key)
        flags = seg.flags
        if flags & SYN and not flags & ACK:
            # A fresh SYN on a pair that already carried a connection starts a new one.
            if conn is not None:
                d = conn.directions[seg.src]
                used = d.started or d.syn_seq is not None or any(x.ended for x in conn.directions.values())
                if used and d.syn_seq != seg.seq:
                    events.extend(self._close(conn, time))
                    conn = None
            if conn is None:
                conn = self._new(seg.src, seg.dst)
            conn.flow.server = seg.dst
        elif conn is None:
            if not seg.payload and not flags & SYN:
                return events  # a stray ACK/FIN/RST of a connection we never saw carry data
            conn = self._new(seg.src, seg.dst)
        if flags & SYN and flags & ACK and conn.flow.server is None:
            conn.flow.server = seg.src
        d = conn.directions[seg.src]
        if d.ended:
            return events
        seq = seg.seq
        if flags & SYN:
            if d.syn_seq is None:
                d.syn_seq = seq
                if d.next_seq is None:
                    d.next_seq = (seq + 1) & 0xFFFFFFFF
            seq = (seq + 1) & 0xFFFFFFFF
        if flags & FIN:
            d.fin_seq = (seq + len(seg.payload) + seg.lost) & 0xFFFFFFFF
        if seg.payload or seg.lost:
            if d.next_seq is None:
                d.next_seq = seq  # capture started mid-stream
            self._accept(conn, seg.src, d, seq, seg.payload, seg.lost, time, events)
        if flags & RST:
            events.extend(self._close(conn, time))
        elif d.fin_seq is not None and d.next_seq == d.fin_seq and not d.pending:
            d.ended = True
            events.append(StreamEnd(conn.flow, seg.src, time))
        if all(x.ended for x in conn.directions.values()):
            self._retire(key, conn)
        return events

    def _accept(
        self,
        conn: _Connection,
        src: Endpoint,
        d: _Direction,
        seq: int,
        data: bytes,
        lost: int,
        time: float | None,
        events: list[CaptureEvent],
    ) -> None:
        assert d.next_seq is not None
        offset = _delta(seq, d.next_seq)
        if offset > 0:
            self._stats.out_of_order_segments += 1
            position = d.position + offset
            old = d.pending.get(position)
            if old is None:
                heapq.heappush(d.order, position)
            if old is None or len(old[0]) + old[1] < len(data) + lost:
                d.pending_bytes += len(data) - (len(old[0]) if old else 0)
                d.pending[position] = (data, lost)
            if d.pending_bytes > MAX_PENDING_BYTES:
                self._skip_hole(conn, src, d, time, events)
            return
        self._deliver(conn, src, d, offset, data, lost, time, events)
        self._drain(conn, src, d, time, events)

    def _deliver(
        self,
        conn: _Connection,
        src: Endpoint,
        d: _Direction,
        offset: int,
        data: bytes,
        lost: int,
        time: float | None,
        events: list[CaptureEvent],
    ) -> None:
        """Deliver a segment that starts ``-offset`` bytes before ``next_seq`` (offset <= 0)."""
        assert d.next_seq is not None
        total = len(data) + lost
        if -offset >= total:
            self._stats.retransmitted_bytes += total
            return
        if offset < 0:
            self._stats.retransmitted_bytes += -offset
            skip = -offset
            if skip >= len(data):
                lost -= skip - len(data)
                data = b""
            else:
                data = data[skip:]
        d.started = True
        if data:
            events.append(StreamData(conn.flow, src, time, data))
        if lost:
            self._stats.tcp_gaps += 1
            events.append(StreamGap(conn.flow, src, time, lost))
        d.next_seq = (d.next_seq + len(data) + lost) & 0xFFFFFFFF
        d.position += len(data) + lost

    def _drain(
        self, conn: _Connection, src: Endpoint, d: _Direction, time: float | None, events: list[CaptureEvent]
    ) -> None:
        """Deliver the pending segments that now start at or before the stream position, in order."""
        while d.order and d.order[0] <= d.position:
            position = heapq.heappop(d.order)
            data, lost = d.pending.pop(position)
            d.pending_bytes -= len(data)
            self._deliver(conn, src, d, position - d.position, data, lost, time, events)

    def _skip_hole(
        self, conn: _Connection, src: Endpoint, d: _Direction, time: float | None, events: list[CaptureEvent]
    ) -> None:
        """Give up on the hole in front of the pending data: report it and go on after it."""
        assert d.next_seq is not None
        missing = d.order[0] - d.position
        self._stats.tcp_gaps += 1
        events.append(StreamGap(conn.flow, src, time, missing))
        d.next_seq = (d.next_seq + missing) & 0xFFFFFFFF
        d.position += missing
        d.started = True
        self._drain(conn, src, d, time, events)

    def _close(self, conn: _Connection, time: float | None) -> list[CaptureEvent]:
        events: list[CaptureEvent] = []
        for src, d in conn.directions.items():
            if d.ended:
                continue
            while d.pending:
                self._skip_hole(conn, src, d, time, events)
            d.ended = True
            events.append(StreamEnd(conn.flow, src, time))
        return events

    def finish(self, time: float | None = None) -> list[CaptureEvent]:
        """End of capture: report what still waits behind holes and end every open direction."""
        events: list[CaptureEvent] = []
        for conn in self._connections.values():
            events.extend(self._close(conn, time))
        self._connections.clear()
        self._closed.clear()
        return events

"""Where a connection's incoming events go: each reply packet to the request waiting for it
(:class:`~rtmu.client.reply_waiter.ReplyWaiter`), each data packet to its subscription's handler
(called and timed by :class:`~rtmu.client.handler_stats.HandlerStats`), and every packet counted
with its time, which the link's health reads.

This is the per-packet path (a map is a million reply packets): the waiter's wake-up is set once per
read, not once per packet.
"""

from __future__ import annotations

from collections.abc import Iterable

from ..protocol.events import (
    DataReceived,
    Event,
    PeerShutdown,
    ReplyComplete,
    ReplyError,
    ReplyFailed,
    ReplyId,
    ReplyPacket,
)
from .call_values import Handler, Packet
from .errors import ClientError, ProtocolFault, ReplyTooLarge
from .handler_stats import HandlerStats
from .reply_waiter import ReplyWaiter


class Inbox:
    """One connection's subscriptions (``handlers``, by data number) and waiting requests (``waiters``)."""

    __slots__ = ("handlers", "last_packet_at", "packets_received", "stats", "waiters")

    def __init__(self) -> None:
        self.handlers: dict[int, Handler] = {}
        self.waiters: dict[ReplyId, ReplyWaiter] = {}
        self.stats = HandlerStats()
        self.last_packet_at: float | None = None
        """When the last packet came (None before the first)."""
        self.packets_received = 0

    def route(self, events: Iterable[Event], now: float) -> bool:
        """Hand each event to its waiter and handler; False when the server shut down."""
        handlers, waiters = self.handlers, self.waiters
        woken: ReplyWaiter | None = None
        for event in events:
            if isinstance(event, ReplyPacket):  # ahead of the rest: a map is a million of these
                reply, payload, swallowed = event
                if not swallowed:
                    waiter = waiters.get(reply)
                    if waiter is not None:  # ReplyWaiter.packet, inlined: its wake-up once per read
                        waiter.count += 1
                        if waiter.queue is not None:
                            waiter.queue.put_nowait(payload)
                        if waiter is not woken:
                            waiter.progress.set()
                            woken = waiter
                if reply.number in handlers:
                    self.deliver(reply.number, reply.name, payload, now)
                else:
                    self.last_packet_at = now
                    self.packets_received += 1
            elif isinstance(event, DataReceived):
                self.deliver(event.command, event.name, event.payload, now)
            elif isinstance(event, ReplyComplete):
                waiter = self.waiters.pop(event.reply, None)
                if waiter is not None:
                    waiter.complete(event.payloads)
            elif isinstance(event, ReplyFailed):
                waiter = self.waiters.pop(event.reply, None)
                if waiter is not None:
                    too_large = event.reason is ReplyError.TOO_LARGE
                    error = ReplyTooLarge(event.message) if too_large else ProtocolFault(event.message)
                    waiter.fail(error, drop_unread=too_large)
            elif isinstance(event, PeerShutdown):
                return False
        return True

    def deliver(self, number: int, name: str | None, payload: bytes, now: float) -> None:
        """One data packet: count it, and call the subscription handler of its data."""
        self.last_packet_at = now
        self.packets_received += 1
        handler = self.handlers.get(number)
        if handler is None:
            return
        self.stats.call(handler, Packet(name or str(number), payload, now))

    def fail_waiters(self, error: ClientError) -> None:
        """The connection ended: every waiting request fails with ``error``."""
        waiters, self.waiters = self.waiters, {}
        for waiter in waiters.values():
            waiter.fail(error)

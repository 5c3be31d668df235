"""The asyncio side of one tracked request: what ``request_once``, ``stream`` and ``follow`` wait on.

The sans-I/O connection decides which packets answer the request and where the reply ends
(:mod:`rtmu.protocol.replies`); :class:`~rtmu.client.connection.AriaClient` hands those events to the
request's :class:`ReplyWaiter`, whose wait bounds every packet with a timeout. A waiter that gives up
(a timeout, or its caller cancelled) is abandoned through its client — its slot stays, so late packets
still line up — and the timeout's error says how far the reply came.
"""

from __future__ import annotations

import asyncio
from collections.abc import AsyncGenerator, Awaitable, Callable

from ..protocol.decoder import DropStats
from ..protocol.events import ReplyId
from ..protocol.packet import MAX_LENGTH
from .errors import ClientError, ClientTimeout, ProtocolFault


class ReplyWaiter:
    """One request's reply as it arrives. ``abandon(waiter)``: give up its slot at the connection;
    ``drops()``: what the connection's decoder threw away (:func:`no_reply` reads why a reply stopped
    coming from it); ``peer``: "host:port", for words.

    ``count``, ``queue`` and ``progress`` are read and written on the connection's per-packet path."""

    __slots__ = (
        "_abandon",
        "_drops",
        "count",
        "error",
        "finished",
        "payloads",
        "peer",
        "progress",
        "queue",
        "reply",
    )

    def __init__(
        self,
        reply: ReplyId,
        streaming: bool,
        *,
        abandon: Callable[[ReplyWaiter], None],
        drops: Callable[[], DropStats],
        peer: str,
        queued: bool = True,
    ) -> None:
        self.reply = reply
        self.queue: asyncio.Queue[bytes | None] | None = asyncio.Queue() if streaming and queued else None
        self.progress = asyncio.Event()
        self.payloads: tuple[bytes, ...] = ()
        self.count = 0
        self.finished = False
        self.error: ClientError | None = None
        self.peer = peer
        self._abandon = abandon
        self._drops = drops

    # -- what the connection reports -----------------------------------------------------------
    def packet(self, payload: bytes) -> None:
        self.count += 1
        if self.queue is not None:
            self.queue.put_nowait(payload)
        self.progress.set()

    def complete(self, payloads: tuple[bytes, ...]) -> None:
        self.finished = True
        self.payloads = payloads
        if self.queue is not None:
            self.queue.put_nowait(None)
        self.progress.set()

    def fail(self, error: ClientError, *, drop_unread: bool = False) -> None:
        """The reply will not come; ``drop_unread``: a stream's reader gets the error before stale packets."""
        if self.finished:
            return
        self.finished = True
        self.error = error
        if self.queue is not None:
            while drop_unread and not self.queue.empty():
                self.queue.get_nowait()
            self.queue.put_nowait(None)
        self.progress.set()

    # -- how a caller waits --------------------------------------------------------------------
    async def collect(
        self, timeout: float, arrived: Callable[[], Awaitable[object]] | None = None
    ) -> tuple[bytes, ...]:
        """Every payload of the reply, once it has ended; ``timeout`` bounds the wait for each packet.

        ``arrived()``: before a timeout is final, take in what has already arrived (a loop run late
        finds its timer and the answer due together, and the timer runs first); a packet it brings
        means the wait goes on."""
        name = self.reply.name
        try:
            while not self.finished:
                self.progress.clear()
                try:
                    async with asyncio.timeout(timeout):
                        await self.progress.wait()
                except TimeoutError:
                    if arrived is not None:
                        await arrived()
                        if self.progress.is_set():
                            continue
                    got = self.count
                    self._abandon(self)
                    raise no_reply(
                        self._drops(),
                        f"no reply to {name!r} from {self.peer} within {timeout:g} s"
                        + (f" (after {got} packets)" if got else ""),
                    ) from None
        finally:
            if not self.finished:  # cancelled: the slot must not wait for ever either
                self._abandon(self)
        if self.error is not None:
            raise self.error
        return self.payloads

    async def items(self, timeout: float, taken: Callable[[bytes], None]) -> AsyncGenerator[bytes, None]:
        """Each payload as it arrives (nothing kept); ``taken(payload)`` once the reader has it."""
        queue = self.queue
        assert queue is not None
        try:
            while True:
                try:
                    if queue.empty():
                        async with asyncio.timeout(timeout):
                            item = await queue.get()
                    else:  # already here: no timer per packet (a big map is millions of packets)
                        item = queue.get_nowait()
                except TimeoutError:
                    raise no_reply(
                        self._drops(),
                        f"{self.reply.name!r} from {self.peer} stalled for {timeout:g} s "
                        f"after {self.count} packets",
                    ) from None
                if item is None:
                    if self.error is not None:
                        raise self.error
                    return
                taken(item)
                yield item
        finally:
            if not self.finished:
                self._abandon(self)

    async def follow(self, timeout: float, progress: Callable[[int], None] | None) -> int:
        """Wait for the reply's end, packets read by its end test alone; ``progress(count)`` after each
        burst. Returns the packet count."""
        name = self.reply.name
        try:
            while not self.finished:
                self.progress.clear()
                got = self.count
                try:
                    async with asyncio.timeout(timeout):
                        await self.progress.wait()
                except TimeoutError:
                    self._abandon(self)
                    raise no_reply(
                        self._drops(),
                        f"{name!r} from {self.peer} stalled for {timeout:g} s after {got} packets"
                        if got
                        else f"no reply to {name!r} from {self.peer} within {timeout:g} s",
                    ) from None
                if progress is not None and self.count != got:
                    progress(self.count)
        finally:
            if not self.finished:
                self._abandon(self)
        if self.error is not None:
            raise self.error
        return self.count


def no_reply(drops: DropStats, message: str) -> ClientError:
    """A timeout, unless the server sent a packet over ARIA's limit: that is then why (dropped)."""
    size = drops.largest_over_limit
    if size:
        limit = f"{MAX_LENGTH:,}".replace(",", " ")
        return ProtocolFault(
            f"{message}: the server sent a packet of {size} bytes, over ArNetworking's "
            f"{limit}-byte limit, so it was dropped"
        )
    return ClientTimeout(message)

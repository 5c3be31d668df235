"""A :class:`~rtmu.client.link.Link` that hands every byte chunk, both ways, to a recorder.

It sits between the client and its real link (TCP), so the client and the session
need no change: what ``AriaClient`` reads and writes is exactly what is recorded.
Each chunk costs one timestamp and one non-blocking queue put on the network loop.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from ..client.link import Link, LinkWrapper, Opener
from .items import RawChunk

RawSink = Callable[[RawChunk], object]


class TeeLink(LinkWrapper):
    """Wraps ``inner``; ``sink`` gets every chunk read (``s2c``) and written (``c2s``) on ``conn``."""

    def __init__(self, inner: Link, conn: int, sink: RawSink) -> None:
        super().__init__(inner)
        self.conn = conn
        self.sink = sink

    async def read(self, max_bytes: int) -> bytes:
        data = await self.inner.read(max_bytes)
        if data:
            self.sink(RawChunk(self.conn, "s2c", bytes(data), time.time_ns()))
        return data

    def write(self, data: bytes) -> None:
        self.inner.write(data)
        if data:
            self.sink(RawChunk(self.conn, "c2s", bytes(data), time.time_ns()))


def tee_opener(inner: Opener, opened: Callable[[str, int], tuple[int, RawSink] | None]) -> Opener:
    """An opener whose links are tee'd: ``opened(host, port)`` → (connection number, sink), or None."""

    async def open_link(host: str, port: int) -> Link:
        link = await inner(host, port)
        tee = opened(host, port)
        if tee is None:
            return link
        conn, sink = tee
        return TeeLink(link, conn, sink)

    return open_link

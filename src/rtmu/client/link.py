"""Where an :class:`~rtmu.client.connection.AriaClient`'s bytes come from and go to.

A :class:`Link` is a byte pipe with the few operations the client needs; the
client never touches a socket itself. :func:`open_tcp` (the default) gives a
live TCP connection; :class:`RecordingLink` wraps any link and keeps what it
read; :class:`ReplayLink` plays such a recording back. So a live robot, a
recorded session and a test feed all run through the same client code.
"""

from __future__ import annotations

import array
import asyncio
import contextlib
import fcntl
import socket
import termios
from collections.abc import Awaitable, Callable, Iterable
from dataclasses import dataclass
from typing import Protocol


class Link(Protocol):
    """A connected byte stream. ``read`` returns ``b""`` once the peer has closed."""

    async def read(self, max_bytes: int) -> bytes: ...

    def write(self, data: bytes) -> None: ...

    def backlog(self) -> int:
        """Bytes written but not yet handed to the OS (a peer that stops reading makes this grow)."""
        ...

    def unread(self) -> int:
        """Bytes that have arrived but not yet been read: in the kernel's socket and in the stream's
        buffer. A status among them is not late, however long the machine took to run us."""
        ...

    def is_closing(self) -> bool: ...

    async def drain(self) -> None: ...

    def finish_writing(self) -> None:
        """Half-close: nothing more will be written, but the peer's bytes can still be read.

        A socket closed while the peer's data sits unread in it is *reset*, and a server whose
        next write meets that reset may drop our last packets (the stop) unread. Saying "no
        more" first and reading until the peer closes lets it read everything we sent.
        """
        ...

    def close(self) -> None:
        """Close after what was written has left; :meth:`wait_closed` waits for it."""
        ...

    async def wait_closed(self) -> None: ...

    def abort(self) -> None:
        """Cut at once, dropping anything unsent."""
        ...


READ_CHUNK = 1 << 16
"""The most one read asks of a link."""

Opener = Callable[[str, int], Awaitable[Link]]
"""``await opener(host, port)`` → a connected :class:`Link`; raises ``OSError`` like ``open_connection``."""


class StreamLink:
    """A :class:`Link` over an asyncio reader/writer pair (a TCP socket)."""

    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.reader = reader
        self.writer = writer

    async def read(self, max_bytes: int) -> bytes:
        try:
            return await self.reader.read(max_bytes)
        except OSError:
            # The stream's own "closed" future holds the same error. Nobody else awaits it, so
            # asyncio would print "Future exception was never retrieved" whenever the garbage
            # collector happens to free it before the protocol (a reset link under rtmu drive did).
            with contextlib.suppress(Exception):
                await self.writer.wait_closed()
            raise

    def write(self, data: bytes) -> None:
        self.writer.write(data)

    def backlog(self) -> int:
        return self.writer.transport.get_write_buffer_size()

    def unread(self) -> int:
        buffered = len(getattr(self.reader, "_buffer", b""))  # (asyncio keeps it private; 0 if renamed)
        sock = self.writer.get_extra_info("socket")
        if sock is None or self.writer.is_closing():
            return buffered
        return buffered + kernel_unread(sock.fileno())

    def is_closing(self) -> bool:
        return self.writer.is_closing()

    async def drain(self) -> None:
        await self.writer.drain()

    def finish_writing(self) -> None:
        if not self.writer.is_closing() and self.writer.can_write_eof():
            with contextlib.suppress(OSError):
                self.writer.write_eof()

    def close(self) -> None:
        self.writer.close()

    async def wait_closed(self) -> None:
        await self.writer.wait_closed()

    def abort(self) -> None:
        transport = self.writer.transport
        if not transport.is_closing():
            transport.abort()


def kernel_unread(fd: int) -> int:
    """Bytes waiting in socket ``fd``'s receive queue (``FIONREAD``); 0 if the kernel will not say."""
    count = array.array("i", [0])
    try:
        fcntl.ioctl(fd, termios.FIONREAD, count, True)
    except OSError:
        return 0
    return count[0]


async def open_tcp(host: str, port: int) -> Link:
    """The default opener: TCP with Nagle off (a stop must not wait for an ACK)."""
    reader, writer = await asyncio.open_connection(host, port)
    sock = writer.get_extra_info("socket")
    if sock is not None:
        with contextlib.suppress(OSError):
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return StreamLink(reader, writer)


# -- recording and replay --------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Chunk:
    """One read: its bytes, and how many bytes the client had written before it came."""

    data: bytes
    written_before: int


class LinkWrapper:
    """A link around another one: everything goes to ``inner``; subclasses watch ``read``/``write``."""

    def __init__(self, inner: Link) -> None:
        self.inner = inner

    async def read(self, max_bytes: int) -> bytes:
        return await self.inner.read(max_bytes)

    def write(self, data: bytes) -> None:
        self.inner.write(data)

    def backlog(self) -> int:
        return self.inner.backlog()

    def unread(self) -> int:
        return self.inner.unread()

    def is_closing(self) -> bool:
        return self.inner.is_closing()

    async def drain(self) -> None:
        await self.inner.drain()

    def finish_writing(self) -> None:
        self.inner.finish_writing()

    def close(self) -> None:
        self.inner.close()

    async def wait_closed(self) -> None:
        await self.inner.wait_closed()

    def abort(self) -> None:
        self.inner.abort()


class RecordingLink(LinkWrapper):
    """Wraps a link and keeps every chunk it reads, with the client's output count at that moment."""

    def __init__(self, inner: Link) -> None:
        super().__init__(inner)
        self.chunks: list[Chunk] = []
        self.written = 0

    async def read(self, max_bytes: int) -> bytes:
        data = await self.inner.read(max_bytes)
        if data:
            self.chunks.append(Chunk(data, self.written))
        return data

    def write(self, data: bytes) -> None:
        self.written += len(data)
        self.inner.write(data)


class RecordedLink:
    """What every link that plays a recording shares: no socket, no peer, nothing queued.

    Subclasses read from their recording and count what the client writes; closing (or
    half-closing: nobody is there to wait for) wakes a read that waits on :attr:`_changed`.
    """

    def __init__(self) -> None:
        self._closed = False
        self._changed = asyncio.Event()

    def backlog(self) -> int:
        return 0

    def unread(self) -> int:
        return 0

    def is_closing(self) -> bool:
        return self._closed

    async def drain(self) -> None:
        return None

    def finish_writing(self) -> None:
        self.close()

    def close(self) -> None:
        self._closed = True
        self._changed.set()

    async def wait_closed(self) -> None:
        return None

    def abort(self) -> None:
        self.close()


class ReplayLink(RecordedLink):
    """Plays recorded chunks back, each only once the client has written as much as it had live.

    That gate keeps replies after the requests they answer, so a replayed session sends
    the same requests and matches the same replies as the live one did. After the last
    chunk the link stays open and silent (``eof=True``: it reports the peer closing).
    """

    def __init__(self, chunks: Iterable[Chunk], *, eof: bool = False) -> None:
        super().__init__()
        self.chunks = list(chunks)
        self.eof = eof
        self.position = 0
        """Chunks handed out so far."""
        self.written = bytearray()
        """Everything the client wrote (a test may decode it)."""

    @property
    def exhausted(self) -> bool:
        return self.position >= len(self.chunks)

    async def read(self, max_bytes: int) -> bytes:
        while not self._closed:
            if self.exhausted:
                if self.eof:
                    return b""
            elif len(self.written) >= self.chunks[self.position].written_before:
                await asyncio.sleep(0)  # live, time passed between reads: let the client's tasks run first
                chunk = self.chunks[self.position].data
                self.position += 1
                return chunk
            self._changed.clear()
            await self._changed.wait()
        return b""

    def write(self, data: bytes) -> None:
        self.written += data
        self._changed.set()

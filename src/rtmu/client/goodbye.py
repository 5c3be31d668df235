"""How a connection ends on our side, bounded in time: the goodbye, then a clean close.

Closing a socket with the server's status still unread would *reset* the connection, and a server
whose next write meets the reset can lose our last packets unread — the stop with them (a loaded
simulator lost it 1 time in 15). So the goodbye is written, the link half-closed, and the peer's
bytes read and dropped until it closes (at most :data:`LINGER_TIMEOUT`). :func:`flushed` waits until
what was sent has left (``rtmu drive`` checks that its stop has, before the process is suspended).
"""

from __future__ import annotations

import asyncio
import contextlib

from ..protocol.client_connection import ClientConnection
from .link import READ_CHUNK, Link

CLOSE_TIMEOUT = 0.2
"""How long ``disconnect`` lets the goodbye flush before cutting the socket."""
LINGER_TIMEOUT = 0.5
"""How long ``disconnect`` reads on after its goodbye, waiting for the server to close first."""


async def say_goodbye(conn: ClientConnection, link: Link, reader: asyncio.Task[None] | None) -> None:
    """Send ``conn``'s goodbye on ``link``, let ``reader`` (the read loop, already cancelled) end, read
    on until the server closes, and close. Never raises; bounded by the timeouts above."""
    conn.shutdown()
    data = conn.data_to_send()
    if link.is_closing():
        return
    with contextlib.suppress(OSError):
        link.write(data)
        link.finish_writing()
    if reader is not None and reader is not asyncio.current_task():
        await asyncio.wait({reader}, timeout=CLOSE_TIMEOUT)  # the link has one reader at a time
    await _read_until_closed(link, LINGER_TIMEOUT)
    link.close()
    with contextlib.suppress(Exception):
        await asyncio.wait_for(link.wait_closed(), CLOSE_TIMEOUT)


async def flushed(link: Link, timeout: float = CLOSE_TIMEOUT) -> bool:
    """Wait, at most ``timeout`` s, until everything written has been handed to the kernel.

    True when nothing is left in our buffer. Never raises.
    """
    if link.is_closing():
        return False
    deadline = asyncio.get_running_loop().time() + timeout
    with contextlib.suppress(TimeoutError, OSError):
        async with asyncio.timeout_at(deadline):
            await link.drain()
            while link.backlog() > 0:
                await asyncio.sleep(0.005)
    return not link.is_closing() and link.backlog() == 0


async def _read_until_closed(link: Link, timeout: float) -> None:
    """Read and drop the peer's bytes until it closes (bounded): our socket then closes clean."""
    with contextlib.suppress(Exception):
        async with asyncio.timeout(timeout):
            while await link.read(READ_CHUNK):
                pass

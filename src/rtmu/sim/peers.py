"""The central server's peers: a TCP peer with bounded output, and an operator served by the codec.

Shared by the central port and every forwarder (:mod:`.central`, :mod:`.forwarder`).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import random
from collections.abc import Callable

from rtmu.protocol.auth import UserTable
from rtmu.protocol.datalist import DataList
from rtmu.protocol.events import ClientIntroduced, LoginRefused, PeerShutdown
from rtmu.protocol.server_connection import ServerConnection, ServerState

log = logging.getLogger("rtmu.sim.central")

KEY_RNG = random.SystemRandom()
READ_CHUNK = 65536
MAX_QUEUED = 4 * 1024 * 1024
"""Output waiting for one peer beyond this gets it dropped (a reader that stopped reading)."""
MAX_OPERATORS = 64
"""Operators per port (the central port and each forwarder); one more is closed at once."""


class Peer:
    """One TCP peer: bounded output, abort on any trouble."""

    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.reader = reader
        self.writer = writer
        self.closed = False
        peer = writer.get_extra_info("peername")
        self.address = peer[0] if isinstance(peer, tuple) else str(peer)

    def write(self, data: bytes) -> None:
        if self.closed or not data:
            return
        transport = self.writer.transport
        if transport is None or transport.is_closing():
            self.abort()
            return
        if transport.get_write_buffer_size() + len(data) > MAX_QUEUED:
            log.info("peer %s: %d bytes queued and not read; dropping it", self.address, MAX_QUEUED)
            self.abort()
            return
        self.writer.write(data)

    def abort(self) -> None:
        if self.closed:
            return
        self.closed = True
        transport = self.writer.transport
        if transport is not None:
            transport.abort()

    def close(self) -> None:
        """Goodbye after what is queued (a SHUTDOWN already written)."""
        if self.closed:
            return
        self.closed = True
        with contextlib.suppress(Exception):
            self.writer.close()


class Operator(Peer):
    """An operator logged in to the central port or to a forwarder."""

    def __init__(
        self,
        reader: asyncio.StreamReader,
        writer: asyncio.StreamWriter,
        datalist: DataList,
        users: UserTable | None = None,
    ) -> None:
        super().__init__(reader, writer)
        self.conn = ServerConnection(datalist, users, rng=KEY_RNG)
        self.subscriptions: dict[int, int] = {}
        """Data number → interval this operator asked (−1: broadcasts only)."""

    def flush(self) -> None:
        self.write(self.conn.data_to_send())

    def goodbye(self) -> None:
        self.conn.shutdown()
        self.flush()
        self.close()


async def serve_operator(op: Operator, on_event: Callable[[Operator, object], None]) -> None:
    """Read ``op`` until it goes; every codec event after the login goes to ``on_event``."""
    op.flush()  # the server INTRODUCTION
    try:
        while not op.closed:
            data = await op.reader.read(READ_CHUNK)
            if not data:
                break
            for event in op.conn.receive_data(data):
                if isinstance(event, (LoginRefused, PeerShutdown)):
                    op.flush()
                    return
                if isinstance(event, ClientIntroduced):
                    op.flush()
                on_event(op, event)
                if op.closed:
                    return
            op.flush()
            if op.conn.state in (ServerState.CLOSING, ServerState.CLOSED):
                return
    except (ConnectionError, OSError):
        pass
    finally:
        op.abort()

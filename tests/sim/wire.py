"""A small test client for the simulator: the project's sans-I/O client codec over asyncio streams.

It records every reply by data name so tests can wait for "the next N packets
of X" with a timeout; nothing here sleeps to wait for the robot.
"""

from __future__ import annotations

import asyncio
import contextlib
from collections import defaultdict
from pathlib import Path

from patience import PATIENCE
from rtmu.protocol.client_connection import ClientConnection, ClientState
from rtmu.protocol.events import DataListReady, DataReceived, PeerShutdown, Rejected

TIMEOUT = 10.0


def run(coro, timeout: float = 60.0):
    """Run a scenario with an overall deadline (× PATIENCE), so a broken server fails the test instead
    of hanging it. The scenarios run simulated time flat out: on a busy machine they need more wall time."""
    return asyncio.run(asyncio.wait_for(coro, timeout * PATIENCE))


async def eventually(predicate, timeout: float = TIMEOUT, what: str = "the condition") -> None:
    """Poll server-side state that no client packet announces (a socket's queue, a session closing)."""

    async def poll() -> None:
        while not predicate():
            await asyncio.sleep(0.005)

    try:
        await asyncio.wait_for(poll(), timeout * PATIENCE)
    except TimeoutError:
        raise AssertionError(f"timed out waiting for {what}") from None


class WireClient:
    def __init__(self, user: str = "", password: str = "", **kw) -> None:
        self.conn = ClientConnection(user, password, **kw)
        self.reader: asyncio.StreamReader | None = None
        self.writer: asyncio.StreamWriter | None = None
        self.received: dict[str, list[bytes]] = defaultdict(list)
        self.rejected: Rejected | None = None
        self.shutdown = False
        self.eof = False
        self._changed = asyncio.Event()
        self._task: asyncio.Task[None] | None = None

    async def open(self, port: int, *, login: bool = True) -> WireClient:
        self.reader, self.writer = await asyncio.open_connection("127.0.0.1", port)
        self._task = asyncio.create_task(self._pump())
        if login:
            await self.until(lambda: self.conn.state in (ClientState.CONNECTED, ClientState.REJECTED))
        return self

    async def _pump(self) -> None:
        assert self.reader is not None
        try:
            while True:
                data = await self.reader.read(65536)
                if not data:
                    break
                for ev in self.conn.receive_data(data):
                    if isinstance(ev, DataReceived):
                        self.received[ev.name or str(ev.command)].append(ev.payload)
                    elif isinstance(ev, Rejected):
                        self.rejected = ev
                    elif isinstance(ev, PeerShutdown):
                        self.shutdown = True
                    elif isinstance(ev, DataListReady):
                        pass
                self._flush()
                self._changed.set()
        except (ConnectionError, OSError):
            pass
        finally:
            self.eof = True
            self._changed.set()

    def _flush(self) -> None:
        data = self.conn.data_to_send()
        if data and self.writer is not None and not self.writer.is_closing():
            self.writer.write(data)

    async def until(self, predicate, timeout: float = TIMEOUT) -> None:
        async def wait() -> None:
            while not predicate():
                if self.eof and not predicate():
                    raise ConnectionError("server closed the connection")
                self._changed.clear()
                await self._changed.wait()

        await asyncio.wait_for(wait(), timeout)

    async def wait_for(self, name: str, count: int = 1, timeout: float = TIMEOUT) -> list[bytes]:
        await self.until(lambda: len(self.received[name]) >= count, timeout)
        return self.received[name]

    def request(self, name: str, interval_ms: int, args: bytes = b"") -> None:
        self.conn.request(name, interval_ms, args)
        self._flush()

    def request_stop(self, name: str) -> None:
        self.conn.request_stop(name)
        self._flush()

    def once(self, name: str, args: bytes = b"") -> None:
        self.conn.request_once(name, args)
        self._flush()

    async def ask(self, name: str, args: bytes = b"", count: int = 1) -> list[bytes]:
        """Request once and wait for ``count`` new replies; returns them."""
        before = len(self.received[name])
        self.once(name, args)
        got = await self.wait_for(name, before + count)
        return got[before : before + count]

    async def barrier(self) -> None:
        """Wait until the server has handled everything sent so far (TCP keeps order)."""
        await self.ask("getSafeDrive")

    def send_raw(self, data: bytes) -> None:
        assert self.writer is not None
        self.writer.write(data)

    async def close(self, *, goodbye: bool = True) -> None:
        if self.writer is not None:
            if goodbye and not self.writer.is_closing():
                self.conn.shutdown()
                self._flush()
            self.writer.close()
            with contextlib.suppress(TimeoutError, ConnectionError, OSError):
                await asyncio.wait_for(self.writer.wait_closed(), 2.0)
        if self._task is not None:
            self._task.cancel()
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await self._task


def captured_server_packets(path: Path):
    """(packet, flow id) the server sent in a captured session, in order (the server sent the first bytes)."""
    from rtmu.capture import StreamData, open_capture
    from rtmu.protocol.decoder import PacketDecoder

    decoders: dict[object, PacketDecoder] = {}
    server_of: dict[int, object] = {}
    for ev in open_capture(path).events():
        if not isinstance(ev, StreamData):
            continue
        server = server_of.setdefault(ev.flow.id, ev.flow.server or ev.src)
        if ev.src != server:
            continue
        dec = decoders.setdefault((ev.flow.id, ev.src), PacketDecoder())
        for packet in dec.feed(ev.data):
            yield packet, ev.flow.id


def captured_datalist(path: Path):
    """The data list a captured server sent on its first connection."""
    from rtmu.protocol.datalist import DataList

    dl = DataList()
    first_flow = None
    for packet, flow in captured_server_packets(path):
        first_flow = first_flow if first_flow is not None else flow
        if flow == first_flow:
            dl.absorb(packet)
    return dl

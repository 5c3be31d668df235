"""The robot's half of ARIA's central server (``ArClientSwitchManager``): connect OUT and switch.

A robot started with ``SimConfig.switch_to`` logs in to the central server's robot port as an ordinary
client, checks that it lists ``switch`` (else it is not a central server), asks ``switch`` once with the
robot's name, and on the empty reply serves that same socket as if a client had connected to it (the
central server then logs in as a client; the robot's refusal of direct logins, reason 2, does not apply
to it). When the switched connection ends it tries again after ``switch_retry`` seconds (ARIA: 10 s);
a central server that promised heartbeats and sends none for ``switch_silence`` seconds is dropped.
The robot also lists ``centralHeartbeat`` (answered empty) and ``centralServerHeartbeat`` (noted).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import time
from collections.abc import Awaitable, Callable, Iterable

from rtmu.protocol.client_connection import ClientConnection
from rtmu.protocol.datalist import DataEntry, DataList
from rtmu.protocol.errors import ProtocolError
from rtmu.protocol.events import DataListReady, DataReceived, PeerShutdown, Rejected, ReplyPacket
from rtmu.protocol.payloads.central import CentralHeartbeat, CentralServerHeartbeat, SwitchRequest

from .handlers import Call, Handler, Reply

log = logging.getLogger("rtmu.sim.switch")

SWITCH_TIMEOUT = 10.0
"""Seconds for the central server to log us in and accept the switch."""

Serve = Callable[[asyncio.StreamReader, asyncio.StreamWriter], Awaitable[None]]


def parse_address(text: str, default_port: int = 5000) -> tuple[str, int]:
    """``HOST[:PORT]`` of a central server's robot port (ARIA's default 5000)."""
    host, sep, port = text.rpartition(":")
    if not sep:
        return text, default_port
    if not port.isdigit() or not 1 <= int(port) <= 65535:
        raise ValueError(f"bad central server address {text!r}: use HOST[:PORT]")
    return host, int(port)


class Heartbeats:
    """When the central server's ``centralServerHeartbeat`` last came (monotonic seconds)."""

    def __init__(self) -> None:
        self.last = time.monotonic()
        self.count = 0

    def beat(self) -> None:
        self.last = time.monotonic()
        self.count += 1


def add_switch_data(datalist: DataList, handlers: dict[str, Handler]) -> Heartbeats:
    """The two heartbeat data ARIA's switch manager adds to a robot server, at the end of its list;
    the returned :class:`Heartbeats` hears the central server's."""
    last = max((e.number for e in datalist), default=255)
    for offset, (name, flags) in enumerate(
        ((CentralHeartbeat.DATA_NAME, "RETURN_SINGLE"), (CentralServerHeartbeat.DATA_NAME, "RETURN_SINGLE"))
    ):
        if name not in datalist:
            what = "central server heartbeat"
            datalist.add(DataEntry(last + 1 + offset, name, what, "none", "none", "RobotInfo", flags))
    heartbeats = Heartbeats()

    def central_server_heartbeat(call: Call) -> Iterable[Reply]:
        heartbeats.beat()
        return []

    handlers[CentralHeartbeat.DATA_NAME] = _central_heartbeat
    handlers[CentralServerHeartbeat.DATA_NAME] = central_server_heartbeat
    return heartbeats


def _central_heartbeat(call: Call) -> Iterable[Reply]:
    return [CentralHeartbeat().encode()]


async def ask_switch(
    reader: asyncio.StreamReader, writer: asyncio.StreamWriter, name: str
) -> DataList | None:
    """Log in to the central server's robot port and have ``switch`` accepted: what it lists (None: it
    lists no ``switch``, so it is not a central server)."""
    conn = ClientConnection()
    number: int | None = None
    while True:
        data = await reader.read(65536)
        if not data:
            raise ConnectionError("the central server closed the connection")
        events = conn.receive_data(data)
        for event in events:
            if isinstance(event, Rejected):
                raise ConnectionError(f"the central server refused us (reason {event.reason}: {event.text})")
            if isinstance(event, PeerShutdown):
                raise ConnectionError("the central server shut the connection down")
            if isinstance(event, DataListReady):
                number = conn.datalist.number(SwitchRequest.DATA_NAME)
                if number is None:
                    return None
                conn.send(SwitchRequest(name))
            elif isinstance(event, (DataReceived, ReplyPacket)) and number is not None:
                command = event.command if isinstance(event, DataReceived) else event.reply.number
                if command == number:
                    writer.write(conn.data_to_send())
                    return conn.datalist
        writer.write(conn.data_to_send())


async def switch_loop(
    host: str,
    port: int,
    name: str,
    retry: float,
    serve: Serve,
    heartbeats: Heartbeats | None = None,
    silence: float = 120.0,
) -> None:
    """Switch to the central server, serve the switched socket, and start again when it ends.

    A central server that lists ``centralServerHeartbeat`` promises one a second: after ``silence``
    seconds without one the link is taken for dead (no reset ever came) and dropped, as ARIA's
    ``RobotFromCentralServerTimeoutInMins`` does.
    """
    while True:
        writer: asyncio.StreamWriter | None = None
        try:
            reader, writer = await asyncio.open_connection(host, port)
            async with asyncio.timeout(SWITCH_TIMEOUT):
                listed = await ask_switch(reader, writer, name)
            if listed is not None:
                log.info("switched to the central server at %s:%d as %r", host, port, name)
                watch = heartbeats if CentralServerHeartbeat.DATA_NAME in listed else None
                await _serve_watched(serve(reader, writer), writer, watch, silence)
                log.info("lost the central server at %s:%d; trying again in %g s", host, port, retry)
            else:
                log.info("%s:%d lists no 'switch': not a central server", host, port)
        except (OSError, TimeoutError, ProtocolError) as exc:
            log.info("cannot switch to %s:%d: %s", host, port, exc or type(exc).__name__)
        finally:
            if writer is not None:
                with contextlib.suppress(Exception):
                    writer.close()
        await asyncio.sleep(retry)


async def _serve_watched(
    serving: Awaitable[None], writer: asyncio.StreamWriter, heartbeats: Heartbeats | None, silence: float
) -> None:
    task = asyncio.ensure_future(serving)
    if heartbeats is None:
        await task
        return
    heartbeats.last = time.monotonic()
    try:
        while not task.done():
            await asyncio.wait({task}, timeout=min(1.0, silence / 4))
            if not task.done() and time.monotonic() - heartbeats.last > silence:
                log.info("no heartbeat from the central server for %g s; dropping the link", silence)
                transport = writer.transport
                if transport is not None:
                    transport.abort()
                await task
    finally:
        if not task.done():
            task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await task

"""The robot's half of ARIA's central server (``ArClientSwitchManager``): connect OUT and switch.

A robot started with ``SimConfig.switch_to`` logs in to the central server's robot port as an ordinary
client, checks that it lists ``switch`` (else it is not a central server), asks ``switch`` once with the
robot's name, and on the empty reply serves that same socket as if a client had connected to it (the
central server then logs in as a client; the robot's refusal of direct logins, reason 2, does not apply
to it). When the switched connection ends it tries again after ``switch_retry`` seconds (ARIA: 10 s).
The robot also lists ``centralHeartbeat`` (answered empty) and ``centralServerHeartbeat`` (noted).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
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


def add_switch_data(datalist: DataList, handlers: dict[str, Handler]) -> None:
    """The two heartbeat data ARIA's switch manager adds to a robot server, at the end of its list."""
    last = max((e.number for e in datalist), default=255)
    for offset, (name, flags) in enumerate(
        ((CentralHeartbeat.DATA_NAME, "RETURN_SINGLE"), (CentralServerHeartbeat.DATA_NAME, "RETURN_SINGLE"))
    ):
        if name not in datalist:
            what = "central server heartbeat"
            datalist.add(DataEntry(last + 1 + offset, name, what, "none", "none", "RobotInfo", flags))
    handlers[CentralHeartbeat.DATA_NAME] = _central_heartbeat
    handlers[CentralServerHeartbeat.DATA_NAME] = _central_server_heartbeat


def _central_heartbeat(call: Call) -> Iterable[Reply]:
    return [CentralHeartbeat().encode()]


def _central_server_heartbeat(call: Call) -> Iterable[Reply]:
    return []


async def ask_switch(reader: asyncio.StreamReader, writer: asyncio.StreamWriter, name: str) -> bool:
    """Log in to the central server's robot port and have ``switch`` accepted; False if it is not one."""
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
                    return False
                conn.send(SwitchRequest(name))
            elif isinstance(event, (DataReceived, ReplyPacket)) and number is not None:
                command = event.command if isinstance(event, DataReceived) else event.reply.number
                if command == number:
                    writer.write(conn.data_to_send())
                    return True
        writer.write(conn.data_to_send())


async def switch_loop(host: str, port: int, name: str, retry: float, serve: Serve) -> None:
    """Switch to the central server, serve the switched socket, and start again when it ends."""
    while True:
        writer: asyncio.StreamWriter | None = None
        try:
            reader, writer = await asyncio.open_connection(host, port)
            async with asyncio.timeout(SWITCH_TIMEOUT):
                accepted = await ask_switch(reader, writer, name)
            if accepted:
                log.info("switched to the central server at %s:%d as %r", host, port, name)
                await serve(reader, writer)
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

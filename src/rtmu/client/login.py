"""The start of a connection: open the link, then log in until the data list is complete.

Each failure is the client's own typed error, in words that say what the peer is: a refused or
unreachable address, a peer that is not an ArNetworking server (a text banner, or bytes without one
valid packet), a refused login (with the protocol string the server wants, where it says), a peer
that closes or shuts down. The caller bounds both steps with one deadline.
"""

from __future__ import annotations

import asyncio
import socket
from collections.abc import Callable

from ..base.i18n import N_, Said
from ..base.refusals import protocol_refusal
from ..base.units import Quantity
from ..protocol.client_connection import ClientConnection
from ..protocol.commands import RejectReason
from ..protocol.errors import ProtocolError
from ..protocol.events import DataListReady, DataReceived, PeerShutdown, Rejected
from .errors import (
    ClientTimeout,
    ConnectionFailed,
    ConnectionRefused,
    HostNotFound,
    LoginRejected,
    ProtocolFault,
    ServerClosed,
)
from .link import READ_CHUNK, Link, Opener

NOT_ARIA_AFTER = 4096
"""Bytes received during login without one valid packet after which the peer is not ArNetworking
(a real server's introduction is one small packet, sent at once)."""
TEXT_BANNERS = (b"HTTP/", b"SSH-", b"RFB ", b"220 ", b"220-", b"+OK", b"* OK")
"""How other common servers open a connection: such a peer is reported at once, not after --timeout."""


async def open_link(opener: Opener, host: str, port: int, deadline: float, timeout: float) -> Link:
    """``opener(host, port)`` by ``deadline`` (loop time; ``timeout`` its length, for the words)."""
    try:
        async with asyncio.timeout_at(deadline):
            return await opener(host, port)
    except TimeoutError:
        raise ClientTimeout(
            Said(
                N_("connecting to {where} timed out after {timeout}"),
                where=f"{host}:{port}",
                timeout=Quantity(timeout, "s", None),
            )
        ) from None
    except ConnectionRefusedError:
        raise ConnectionRefused(
            Said(
                N_("connection refused by {where} (is the robot server running on that port?)"),
                where=f"{host}:{port}",
            )
        ) from None
    except socket.gaierror as exc:
        raise HostNotFound(
            Said(N_("cannot find host {host}: {error}"), host=repr(host), error=exc.strerror or exc)
        ) from None
    except OSError as exc:
        raise ConnectionFailed(
            Said(N_("cannot connect to {where}: {error}"), where=f"{host}:{port}", error=exc.strerror or exc)
        ) from None


async def log_in(
    link: Link,
    conn: ClientConnection,
    peer: str,
    clock: Callable[[], float],
    flush: Callable[[], None],
    deliver: Callable[[int, str | None, bytes, float], None],
) -> None:
    """Read from ``link`` into ``conn`` until its data list is complete, sending its answers
    (``flush``); data the server sends meanwhile goes to ``deliver(number, name, payload, now)``.
    ``peer`` ("host:port") is for the words. Unbounded in time: the caller sets the deadline."""
    received = 0
    while True:
        try:
            data = await link.read(READ_CHUNK)
        except OSError as exc:
            raise ServerClosed(
                Said(N_("the connection broke during login: {error}"), error=exc.strerror or exc)
            ) from None
        if not data:
            raise ServerClosed(Said(N_("{peer} closed the connection during login"), peer=peer))
        if received == 0 and data.startswith(TEXT_BANNERS):
            banner = data[:40].split(b"\n")[0].decode("ascii", "replace").strip()
            raise ProtocolFault(
                Said(
                    N_("{peer} is not an ArNetworking server (it said {said})"), peer=peer, said=repr(banner)
                )
            )
        received += len(data)
        now = clock()
        try:
            events = conn.receive_data(data, now)
        except ProtocolError as exc:
            raise ProtocolFault(
                Said(N_("{peer} is not an ArNetworking server: {error}"), peer=peer, error=exc)
            ) from None
        if received >= NOT_ARIA_AFTER and conn.decoder.stats.packets == 0:
            raise ProtocolFault(
                Said(
                    N_("{peer} is not an ArNetworking server ({count} bytes without a single valid packet)"),
                    peer=peer,
                    count=received,
                )
            )
        flush()
        ready = False
        for event in events:
            if isinstance(event, Rejected):
                raise login_rejected(conn, event)
            if isinstance(event, PeerShutdown):
                raise ServerClosed(Said(N_("{peer} shut the connection down during login"), peer=peer))
            if isinstance(event, DataListReady):
                ready = True
            elif isinstance(event, DataReceived):
                deliver(event.command, event.name, event.payload, now)
        if ready:
            return


def login_rejected(conn: ClientConnection, event: Rejected) -> LoginRejected:
    """The refusal as the operator's error; reason 4 names the protocol string the server wants."""
    wanted = conn.wanted_protocol()
    advice = ""
    if event.reason == RejectReason.PROTOCOL_VERSION_MISMATCH and wanted is not None:
        advice = protocol_refusal(wanted, conn.sent_protocol_version or "")
    return LoginRejected(event.reason, event.text, advice, wanted)

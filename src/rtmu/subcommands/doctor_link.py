"""``rtmu doctor``'s checks of the link itself: the UDP port, and the status stream's timing.

Split from :mod:`rtmu.subcommands.doctor` (which walks the steps in order): each works on the
doctor's bare codec connection and reports through what it is given, so it holds no state of its own.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from ..base.i18n import N_, Said
from ..base.units import Quantity

if TYPE_CHECKING:
    import asyncio

    from ..protocol.client_connection import ClientConnection
    from ..protocol.events import ServerIntroduction

READ_CHUNK = 65536
UDP_WAIT_S = 2.0
"""How long the UDP port has to answer our introduction."""


async def check_udp(address: str, intro: ServerIntroduction, ok: Callable[..., None]) -> None:
    """The server's UDP port: does it answer our introduction with our key? (A warning at worst:
    RTMU speaks TCP only.) ``ok`` records the step (``Doctor.ok``)."""
    import asyncio

    from ..client.diagnosis import Step
    from ..protocol.commands import ClientCommand, ServerCommand
    from ..protocol.decoder import PacketDecoder
    from ..protocol.fields import FieldReader, FieldWriter
    from ..protocol.packet import encode_packet

    if intro.udp_port == 0:
        ok(Step.UDP, Said(N_("not used: the server is TCP-only (UDP port 0)")), "not_checked")
        return
    loop = asyncio.get_running_loop()
    answered = loop.create_future()

    class Listener(asyncio.DatagramProtocol):
        def datagram_received(self, data: bytes, addr: Any) -> None:
            for packet in PacketDecoder().feed(data):
                if packet.command == ServerCommand.UDP_INTRODUCTION and not answered.done():
                    key = FieldReader(packet.payload).byte4("intro key", default=-1)
                    answered.set_result(key == intro.intro_key)

    transport, _ = await loop.create_datagram_endpoint(Listener, remote_addr=(address, intro.udp_port))
    try:
        hello = encode_packet(ClientCommand.UDP_INTRODUCTION, FieldWriter().ubyte4(intro.auth_key).bytes())
        transport.sendto(hello)
        try:
            async with asyncio.timeout(UDP_WAIT_S):
                good = await answered
        except TimeoutError:
            ok(
                Step.UDP,
                Said(
                    N_("no answer on UDP port {port} within {timeout}"),
                    port=intro.udp_port,
                    timeout=Quantity(UDP_WAIT_S, "s", None),
                ),
                "warn",
                N_(
                    "UDP may be blocked between here and the robot; RTMU uses TCP only, so this does not "
                    "stop RTMU (ARIA's own clients fall back to TCP after a few seconds)"
                ),
            )
            return
        if good:
            ok(
                Step.UDP,
                Said(N_("UDP port {port} answers (the server knew our key)"), port=intro.udp_port),
            )
        else:
            ok(
                Step.UDP,
                Said(N_("UDP port {port} answered with a wrong key"), port=intro.udp_port),
                "warn",
            )
    finally:
        transport.close()


async def learn_link_timing(
    conn: ClientConnection, reader: asyncio.StreamReader, flush: Callable[[], None], name: str, seconds: float
) -> dict[str, Any]:
    """Subscribe to status at ``rtmu drive``'s rate for ``seconds`` and learn its timing by the rule
    the window and ``rtmu drive`` use (``base.link_timing``); ``flush`` sends what ``conn`` queued."""
    import asyncio

    from ..client.drive_guard import STALE_INTERVALS, STATUS_INTERVAL_MS
    from ..client.health import HealthMonitor
    from ..protocol.errors import ProtocolError
    from ..protocol.events import DataReceived

    number = conn.number_of(name)
    health = HealthMonitor(STATUS_INTERVAL_MS / 1000.0, stale_intervals=STALE_INTERVALS)
    loop = asyncio.get_running_loop()
    start = loop.time()
    health.start(start)
    conn.request(name, STATUS_INTERVAL_MS)
    flush()
    last, longest = None, 0.0
    with contextlib.suppress(TimeoutError, OSError):
        async with asyncio.timeout(seconds):
            while data := await reader.read(READ_CHUNK):
                now = loop.time()
                for event in conn.receive_data(data):
                    if isinstance(event, DataReceived) and event.command == number:
                        longest = max(longest, now - last) if last is not None else 0.0
                        last = now
                        health.note_status(now)
                flush()
    with contextlib.suppress(ProtocolError, KeyError):
        conn.request_stop(name)
        flush()
    timing = health.timing(loop.time())
    return {
        "status_every_ms": STATUS_INTERVAL_MS,
        "arrived": timing.samples + (1 if last is not None else 0),
        "longest_gap_ms": round(longest * 1000),
        "jitter_ms": round(timing.jitter * 1000),
        "stale_after_s": round(timing.settled, 2),
    }

"""Malformed control packets reach the simulator as typed errors: logins refused, REQUESTs ignored.

Nothing may escape as an exception: the session's catch-all would close the client
without a REJECTED (and log an error), which these tests would see.
"""

from __future__ import annotations

import asyncio
import logging

import pytest

from rtmu.protocol.commands import ClientCommand, ServerCommand
from rtmu.protocol.decoder import PacketDecoder
from rtmu.protocol.packet import Packet, encode_packet
from rtmu.protocol.payloads.control import Rejected, ServerIntroduction
from rtmu.sim import SimConfig, SimServer

from .wire import TIMEOUT, WireClient, run

SHORT_INTRODUCTION = encode_packet(ClientCommand.INTRODUCTION, b"\x00\x00bob\x00\x01\x02")  # digest cut short


async def _packets_until_eof(reader: asyncio.StreamReader) -> list[Packet]:
    decoder = PacketDecoder()
    packets: list[Packet] = []
    while data := await asyncio.wait_for(reader.read(65536), TIMEOUT):
        packets += decoder.feed(data)
    return packets


async def _refused(cfg: SimConfig) -> tuple[list[Packet], int, int]:
    """A short INTRODUCTION: what came back until the close, the count, and whether a good login works."""
    server = SimServer(cfg)
    await server.start()
    try:
        reader, writer = await asyncio.open_connection("127.0.0.1", server.port)
        writer.write(SHORT_INTRODUCTION)
        packets = await _packets_until_eof(reader)  # the server closes after refusing
        writer.close()
        good = await WireClient().open(server.port)  # the next client is not affected
        accepted = int(good.rejected is None)
        await good.close()
        return packets, server.malformed_packets, accepted
    finally:
        await server.stop()


@pytest.mark.parametrize(
    ("enforced", "reason"),
    [
        (None, 1),  # the codec's own check: a login it cannot read is a bad user or password
        ("5.0", 4),  # an enforced version comes first, and an unreadable introduction has none
    ],
)
def test_a_malformed_introduction_is_refused_and_closed(caplog, enforced, reason):
    caplog.set_level(logging.INFO, logger="rtmu.sim")
    cfg = SimConfig(port=0, realtime=False)
    if enforced is not None:
        cfg.protocol_version = enforced
    packets, malformed, accepted = run(_refused(cfg))
    assert [p.command for p in packets] == [ServerCommand.INTRODUCTION, ServerCommand.REJECTED]
    ServerIntroduction.decode(packets[0].payload)
    assert Rejected.decode(packets[1].payload).reason == reason
    assert malformed == 1
    if enforced is None:
        assert accepted == 1
    assert not [r for r in caplog.records if r.levelno >= logging.ERROR]
    assert any("malformed control packet" in r.getMessage() for r in caplog.records)


def test_malformed_request_and_request_stop_are_ignored_and_counted(caplog):
    caplog.set_level(logging.INFO, logger="rtmu.sim")

    async def scenario() -> None:
        server = SimServer(SimConfig(port=0, realtime=False))
        await server.start()
        client = await WireClient().open(server.port)
        client.send_raw(encode_packet(ClientCommand.REQUEST, b"\x08\x01\x00"))  # interval cut short
        client.send_raw(encode_packet(ClientCommand.REQUESTSTOP, b"\x01"))  # half a data number
        client.request("updateNumbers", -1)  # still served, on the same connection
        await client.wait_for("updateNumbers")
        await client.barrier()
        assert server.malformed_packets == 2
        (session,) = server.sessions
        assert list(session.subscriptions) == [client.conn.number_of("updateNumbers")]
        assert not client.eof
        await client.close()
        await server.stop()

    run(scenario())
    assert not [r for r in caplog.records if r.levelno >= logging.ERROR]

"""Packet framing (protocol §1.1–1.4): byte-exact against the document and real ARIA captures."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtmu.capture import StreamData, StreamGap, open_capture
from rtmu.protocol import (
    MAX_LENGTH,
    MAX_PAYLOAD,
    ClientCommand,
    FieldWriter,
    Packet,
    PacketDecoder,
    PacketTooLong,
    ProtocolError,
    ServerCommand,
    encode_packet,
)
from rtmu.protocol.checksum import checksum_naive
from testdata import CAPTURES


def wire(hex_bytes: str) -> bytes:
    return bytes.fromhex(hex_bytes.replace("|", " "))


# -- the document's examples --------------------------------------------------------------------


@pytest.mark.parametrize(
    ("command", "payload", "expected"),
    [
        # §1.3 worked examples A–D
        pytest.param(
            ClientCommand.REQUEST,
            FieldWriter().ubyte2(0x0108).byte4(200).bytes(),
            "0F 0C 0E 00 81 00 08 01 C8 00 00 00 02 51",
            id="A-request",
        ),
        pytest.param(
            ServerCommand.REJECTED,
            FieldWriter().byte2(1).string("").bytes(),
            "0F 0C 0B 00 06 00 01 00 00 00 07",
            id="B-rejected",
        ),
        pytest.param(
            0x0117,
            FieldWriter().double(50).double(0).double(100).double(0).bytes(),
            "0F 0C 13 00 17 01 35 30 00 30 00 31 30 30 00 30 00 C2 4C",
            id="C-ratio-drive",
        ),
        pytest.param(ServerCommand.CONNECTED, b"", "0F 0C 08 00 05 00 00 05", id="D-connected"),
        pytest.param(0x0124, b"", "0F 0C 08 00 24 01 00 25", id="D-empty-data"),
        # §1.1 captured from a real server
        pytest.param(ClientCommand.TCP_ONLY, b"", "0F 0C 08 00 05 00 00 05", id="1.1-client-tcp-only"),
        pytest.param(ServerCommand.TCP_ONLY, b"", "0F 0C 08 00 07 00 00 07", id="1.1-server-tcp-only"),
        pytest.param(0x0119, b"\x01", "0F 0C 09 00 19 01 01 00 18", id="1.1-safe-drive"),
        # §2.5 the C++ client's INTRODUCTION: UDP port 10000, no user, md5("") digest
        pytest.param(
            ClientCommand.INTRODUCTION,
            FieldWriter().ubyte2(10000).string("").raw(hashlib.md5(b"").digest()).string("").byte(0).bytes(),
            "0F 0C 1D 00 02 00 | 10 27 | 00 | D4 1D 8C D9 8F 00 B2 04 E9 80 09 98 EC F8 42 7E"
            " | 00 | 00 | EB 9A",
            id="2.5-client-introduction",
        ),
    ],
)
def test_encode_is_byte_exact(command: int, payload: bytes, expected: str) -> None:
    assert encode_packet(command, payload) == wire(expected)
    assert Packet(command, payload).encode() == wire(expected)
    assert PacketDecoder().feed(wire(expected)) == [Packet(command, payload)]


def test_server_introduction_prefix_matches_the_capture() -> None:
    """§2.4: only the first 40 bytes are printed in the document; they must be ours too."""
    payload = (
        FieldWriter()
        .string("alpha")
        .ubyte2(17272)
        .ubyte4(0x1E564427)
        .ubyte4(0x35E51CAF)
        .string("_yDK=p6JTRp0j_Iq6lNF1xs")
        .string("")
        .bytes()
    )
    data = encode_packet(ServerCommand.INTRODUCTION, payload)
    captured = "0F 0C 31 00 02 00 61 6C 70 68 61 00 78 43 | 27 44 56 1E | AF 1C E5 35 | 5F 79 44 4B"
    assert data.startswith(wire(captured))
    assert len(data) == 0x31


def test_length_counts_the_whole_packet() -> None:
    for n in (0, 1, 2, 100, MAX_PAYLOAD):
        data = encode_packet(300, bytes(n))
        assert len(data) == n + 8
        assert int.from_bytes(data[2:4], "little") == n + 8
        assert data[:2] == b"\x0f\x0c"


@given(st.integers(0, 0xFFFF), st.binary(max_size=3000))
def test_checksum_is_big_endian_over_the_body(command: int, payload: bytes) -> None:
    data = encode_packet(command, payload)
    assert int.from_bytes(data[4:6], "little") == command
    assert data[6:-2] == payload
    assert data[-2:] == checksum_naive(data[:-2]).to_bytes(2, "big")


# -- limits ---------------------------------------------------------------------------------


def test_largest_packet_is_accepted() -> None:
    data = encode_packet(0x0200, bytes(range(256)) * 124 + bytes(MAX_PAYLOAD - 256 * 124))
    assert len(data) == MAX_LENGTH == 32000
    assert PacketDecoder().feed(data)[0].payload == data[6:-2]


def test_one_byte_over_the_limit_is_refused_with_a_clear_message() -> None:
    with pytest.raises(PacketTooLong) as info:
        encode_packet(0x0123, bytes(MAX_PAYLOAD + 1))
    message = str(info.value)
    assert "32001" in message and "32000" in message
    assert str(MAX_PAYLOAD) in message and str(MAX_PAYLOAD + 1) in message
    assert "291" in message  # the command, so the log says which data overflowed
    assert isinstance(info.value, ProtocolError)


def test_far_too_long_payloads_are_refused_too() -> None:
    with pytest.raises(PacketTooLong):
        encode_packet(300, bytes(70000))  # would also wrap the 16-bit length field


@pytest.mark.parametrize("command", [-1, 0x10000])
def test_command_must_fit_16_bits(command: int) -> None:
    with pytest.raises(ValueError, match="16-bit"):
        encode_packet(command, b"")


# -- real ARIA sessions -----------------------------------------------------------------------


Direction = tuple[str, int, str, int]
"""(source address, source port, destination address, destination port)"""


def tcp_streams(path: Path) -> dict[Direction, bytes]:
    """Each TCP direction's bytes, reassembled by the product's capture reader (``rtmu.capture``)."""
    streams: dict[Direction, bytearray] = {}
    for event in open_capture(path).events():
        if isinstance(event, StreamGap):
            raise AssertionError(f"{path.name}: {event.missing} bytes missing from {event.src}")
        if isinstance(event, StreamData):
            dst = event.flow.peer_of(event.src)
            key = (event.src.host, event.src.port, dst.host, dst.port)
            streams.setdefault(key, bytearray()).extend(event.data)
    return {key: bytes(data) for key, data in streams.items()}


def capture_files() -> list[Path]:
    files = sorted(CAPTURES.glob("*.pcap"))
    assert len(files) >= 8, f"the captured ARIA sessions are missing from {CAPTURES}"
    return files


def test_every_captured_packet_decodes_and_re_encodes_to_the_same_bytes() -> None:
    """The captures hold ~65 000 packets from ARIA 2.9.1 itself: none may be dropped or altered."""
    total = 0
    for path in capture_files():
        streams = tcp_streams(path)
        assert streams, path
        for direction, stream in streams.items():
            decoder = PacketDecoder()
            packets = decoder.feed(stream) + decoder.close()
            where = f"{path.name} {direction}"
            assert decoder.stats.dropped == 0, where
            assert decoder.stats.garbage_bytes == 0, where
            assert b"".join(p.encode() for p in packets) == stream, where
            total += len(packets)
    assert total > 60000

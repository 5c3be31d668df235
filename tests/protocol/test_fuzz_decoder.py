"""Adversarial input: the decoder never raises, never grows and never loses a good packet; the
connections above it never fail in any way but a ProtocolError."""

from __future__ import annotations

import random

from hypothesis import given
from hypothesis import strategies as st

from rtmu.protocol import MAX_LENGTH, MAX_PAYLOAD, DataList, Packet, PacketDecoder, ProtocolError
from rtmu.protocol.checksum import checksum_naive
from rtmu.protocol.client_connection import ClientConnection
from rtmu.protocol.packet import MIN_LENGTH
from rtmu.protocol.server_connection import ServerConnection

from .test_decoder import feed_in_chunks, mixed_packets, packets_st


@given(st.lists(st.binary(max_size=300), max_size=30))
def test_never_raises_and_every_byte_is_accounted_for(chunks: list[bytes]) -> None:
    decoder = PacketDecoder()
    delivered = 0
    for chunk in chunks:
        for packet in decoder.feed(chunk):
            delivered += len(packet.payload) + 8
        assert decoder.buffered < MAX_LENGTH
    for packet in decoder.close():
        delivered += len(packet.payload) + 8
    assert decoder.buffered == 0
    assert delivered + decoder.stats.garbage_bytes == sum(map(len, chunks))


SYNC_HEAVY = st.lists(
    st.sampled_from([b"\x0f", b"\x0c", b"\x0f\x0c", b"\x00", b"\x7d", b"\xff", b"\x08\x00", b"\x01"]),
    max_size=60,
).map(b"".join)
"""Garbage made of the bytes that matter: sync halves and plausible length bytes."""

garbage_st = st.one_of(st.binary(max_size=200), SYNC_HEAVY)


@given(st.lists(st.tuples(garbage_st, packets_st), max_size=12), garbage_st, st.data())
def test_every_valid_packet_in_garbage_is_found(
    pieces: list[tuple[bytes, Packet]], trailing: bytes, data: st.DataObject
) -> None:
    planted = [packet for _, packet in pieces]
    stream = b"".join(g + p.encode() for g, p in pieces) + trailing
    cuts = data.draw(st.lists(st.integers(0, len(stream)), max_size=10))
    decoder = PacketDecoder()
    found = feed_in_chunks(decoder, stream, cuts) + decoder.close()
    # Garbage can itself contain a well-formed packet (e.g. 0F 0C 08 00 00 00 00 00); anything
    # delivered must be a real, checksummed packet present in the stream...
    for packet in found:
        assert packet.encode() in stream
    # ...and every planted packet must be among them, in order, unless a packet-shaped accident
    # in the garbage happened to overlap it (then it was consumed, as it would be by ARIA).
    accidental = [p for p in found if p not in planted]
    if not accidental:
        assert found == planted


def reference_decode(stream: bytes) -> tuple[list[Packet], int, int, int]:
    """The documented rules read literally, on the whole stream at once, with the per-byte checksum.

    Returns the packets and the bad-length, bad-checksum and cut-off counts.
    """
    found: list[Packet] = []
    bad_length = bad_checksum = truncated = 0
    pos = 0
    while (start := stream.find(b"\x0f\x0c", pos)) >= 0:
        length = int.from_bytes(stream[start + 2 : start + 4], "little")
        if len(stream) - start < 4:  # a sync pair cut off before its length field
            truncated += 1
            pos = start + 2
        elif not MIN_LENGTH <= length <= MAX_LENGTH:
            bad_length += 1
            pos = start + 4
        elif len(stream) - start < length:  # cut off by the end of the stream: rescan behind the header
            truncated += 1
            pos = start + 2
        elif checksum_naive(stream[start : start + length - 2]) != int.from_bytes(
            stream[start + length - 2 : start + length], "big"
        ):
            bad_checksum += 1
            pos = start + 2
        else:
            found.append(
                Packet(
                    int.from_bytes(stream[start + 4 : start + 6], "little"),
                    stream[start + 6 : start + length - 2],
                )
            )
            pos = start + length
    return found, bad_length, bad_checksum, truncated


def _corrupted(packet: Packet, flip: int) -> bytes:
    raw = bytearray(packet.encode())
    raw[4 + flip % (len(raw) - 4)] ^= 0x5A
    return bytes(raw)


FALSE_HEADERS = st.builds(
    lambda length, body: b"\x0f\x0c" + length.to_bytes(2, "little") + body,
    st.integers(MIN_LENGTH, 200),
    st.binary(max_size=6),
)
"""Headers with short, plausible lengths: their spans end inside the stream, so their checksums run."""
hostile_piece = st.one_of(
    garbage_st,
    FALSE_HEADERS,
    packets_st.map(Packet.encode),
    st.builds(_corrupted, packets_st, st.integers(0, 1000)),
)


@given(st.lists(hostile_piece, max_size=40), st.data())
def test_decoder_matches_the_literal_rules_on_hostile_streams(
    pieces: list[bytes], data: st.DataObject
) -> None:
    """Failed checksums switch the decoder to prefix sums; the packets and counts must not change.

    One count may move by design: a header the decoder gave up as a liar (four checksummed packets
    went on behind it while it waited) is one the literal rules count as cut off at the end, or as a
    bad checksum once its span ends. So the dropped headers are compared in total, and the packets
    exactly (found by hypothesis: ``0F 0C`` followed by four empty packets).
    """
    stream = b"".join(pieces)
    cuts = data.draw(st.lists(st.integers(0, len(stream)), max_size=10))
    decoder = PacketDecoder()
    found = feed_in_chunks(decoder, stream, cuts) + decoder.close()
    packets, bad_length, bad_checksum, truncated = reference_decode(stream)
    assert found == packets
    stats = decoder.stats
    assert stats.bad_length == bad_length
    assert stats.bad_checksum <= bad_checksum and stats.truncated_at_close <= truncated
    assert stats.bad_checksum + stats.truncated_at_close + stats.lying_headers == bad_checksum + truncated


def test_a_liar_before_four_packets_counts_as_a_liar_not_as_cut_off() -> None:
    """The case hypothesis found: the same packets as the literal rules, the header named a liar."""
    empty = b"\x0f\x0c\x08\x00\x00\x00\x00\x00"
    stream = b"\x0f\x0c" + empty * 4
    decoder = PacketDecoder()
    found = decoder.feed(stream) + decoder.close()
    packets, _, _, truncated = reference_decode(stream)
    assert found == packets and len(found) == 4
    assert truncated == 1
    assert (decoder.stats.lying_headers, decoder.stats.truncated_at_close) == (1, 0)


def test_planted_packets_survive_heavy_noise() -> None:
    """A long deterministic soak: random noise rich in sync bytes around 2000 packets."""
    rng = random.Random(2024)
    noise_alphabet = b"\x0f\x0c\x0f\x0c\x00\x08\x7d\xff" + bytes(range(256))
    packets = mixed_packets(rng, 2000)
    parts = []
    for packet in packets:
        parts.append(bytes(rng.choice(noise_alphabet) for _ in range(rng.randrange(0, 40))))
        parts.append(packet.encode())
    stream = b"".join(parts)
    decoder = PacketDecoder()
    found: list[Packet] = []
    pos = 0
    while pos < len(stream):
        step = rng.choice([1, 5, 100, 1460, 9000, 70000])
        found += decoder.feed(stream[pos : pos + step])
        pos += step
        assert decoder.buffered < MAX_LENGTH
    found += decoder.close()
    planted = iter(found)
    assert all(any(p == q for q in planted) for p in packets), "a planted packet was lost"


def test_memory_stays_bounded_under_a_flood_of_false_headers() -> None:
    """Headers claiming 32000 bytes, each failing its checksum, fed in chunks of every size."""
    bogus = b"\x0f\x0c" + MAX_LENGTH.to_bytes(2, "little")
    flood = (bogus + bytes(range(256)) * 4) * 300
    decoder = PacketDecoder()
    rng = random.Random(5)
    pos = 0
    while pos < len(flood):
        step = rng.choice([1, 3, 1000, 40000])
        decoder.feed(flood[pos : pos + step])
        pos += step
        assert decoder.buffered <= MAX_LENGTH
        # Implementation check: the internal buffer also drops what was consumed.
        assert len(decoder._buf) <= 64 * 1024 + MAX_LENGTH + step
    decoder.close()
    assert decoder.stats.packets == 0
    assert decoder.stats.garbage_bytes == len(flood)


def test_largest_payload_through_a_fragmented_stream() -> None:
    packet = Packet(0x4000, random.Random(8).randbytes(MAX_PAYLOAD))
    data = packet.encode() * 3
    decoder = PacketDecoder()
    out = []
    for i in range(0, len(data), 999):
        out += decoder.feed(data[i : i + 999])
    assert out == [packet] * 3


# -- the connections above the decoder --------------------------------------------------------

CONTROL_COMMANDS = st.sampled_from([1, 2, 3, 4, 5, 6, 7, 128, 129, 130, 131, 132, 133, 134])
fuzz_packets = st.lists(
    st.builds(Packet, st.one_of(CONTROL_COMMANDS, st.integers(0, 0xFFFF)), st.binary(max_size=80)),
    max_size=12,
)


def _connected_pair() -> tuple[ClientConnection, ServerConnection]:
    server = ServerConnection(DataList.build([("updateNumbers", "", "", "", "", "")]), rng=random.Random(1))
    client = ClientConnection()
    client.receive_data(server.data_to_send())
    server.receive_data(client.data_to_send())
    client.receive_data(server.data_to_send())
    return client, server


@given(fuzz_packets, st.integers(0, 2))
def test_client_connection_only_ever_raises_protocol_errors(packets: list[Packet], stage: int) -> None:
    """Whatever a hostile server sends, in any state, the client reports events or a ProtocolError."""
    client, _ = _connected_pair()
    if stage == 0:
        client = ClientConnection()
    elif stage == 1:
        client = ClientConnection()
        intro = b"alpha\x00\x00\x00" + bytes(8) + b"key\x00\x00"
        client.receive_data(Packet(2, intro).encode())
    for packet in packets:
        try:
            client.receive_data(packet.encode())
        except ProtocolError:
            return  # the caller closes the connection
    client.data_to_send()


@given(fuzz_packets, st.booleans())
def test_server_connection_never_raises(packets: list[Packet], logged_in: bool) -> None:
    """Whatever a hostile client sends, the server side answers with events, never an exception."""
    server = _connected_pair()[1] if logged_in else ServerConnection(DataList(), rng=random.Random(2))
    for packet in packets:
        server.receive_data(packet.encode())
    server.data_to_send()

"""One lying header cannot stall the stream, and no real packet is ever split or lost for it.

Real packets include big ones (up to ARIA's 32000 bytes) whose random content may embed runs of
valid small packets shorter than :data:`STREAM_GOES_ON`; fake headers (a sync pair and a length
whose body never comes) sit at random places between real packets; the bytes are cut anywhere.
"""

from __future__ import annotations

import random

from hypothesis import given, settings
from hypothesis import strategies as st

from rtmu.protocol import MAX_LENGTH, MAX_PAYLOAD, Packet, PacketDecoder, encode_packet
from rtmu.protocol.decoder import STREAM_GOES_ON

from .test_decoder import feed_in_chunks

STATUS = 0x0108


def status(i: int) -> Packet:
    return Packet(STATUS, i.to_bytes(4, "little") + bytes(15))


def big_payload(seed: int, size: int, runs: int) -> bytes:
    """Random bytes holding ``runs`` runs of back-to-back valid packets, each run too short to prove."""
    rng = random.Random(seed)
    body = bytearray(rng.randbytes(size))
    for _ in range(runs):
        run = b"".join(
            encode_packet(STATUS, rng.randbytes(rng.randrange(0, 30)))
            for _ in range(rng.randrange(1, STREAM_GOES_ON))
        )
        at = rng.randrange(0, max(1, size - len(run) - 2))
        if at + len(run) + 1 <= size:
            body[at : at + len(run) + 1] = run + b"\x00"  # a zero ends the run: runs never join
    return bytes(body)


real_st = st.one_of(
    st.integers(0, 10_000).map(status),
    st.builds(
        lambda seed, size, runs: Packet(0x0120, big_payload(seed, size, runs)),
        st.integers(0, 2**32),
        st.sampled_from([1000, 20000, MAX_PAYLOAD]),
        st.integers(0, 4),
    ),
)
fake_st = st.integers(20_000, MAX_LENGTH).map(lambda n: b"\x0f\x0c" + n.to_bytes(2, "little"))
piece_st = st.tuples(st.lists(fake_st, max_size=3).map(b"".join), real_st)


@settings(max_examples=60, deadline=None)
@given(st.lists(piece_st, min_size=1, max_size=8), st.data())
def test_every_real_packet_once_in_order_and_nothing_waits_behind_a_liar(
    pieces: list[tuple[bytes, Packet]], data: st.DataObject
) -> None:
    # The stream goes on after the last piece, as a live ARIA stream does (status at 10 Hz).
    tail = [status(100_000 + i) for i in range(STREAM_GOES_ON)]
    planted = [p for _, p in pieces] + tail
    stream = b"".join(fakes + p.encode() for fakes, p in pieces) + b"".join(p.encode() for p in tail)
    cuts = data.draw(st.lists(st.integers(0, len(stream)), max_size=12))
    decoder = PacketDecoder()
    found: list[Packet] = []
    last = 0
    for cut in [*sorted(cuts), len(stream)]:
        found += decoder.feed(stream[last:cut])
        # Memory: at most one waiting packet plus what this feed brought.
        assert decoder.buffered <= MAX_LENGTH + (cut - last)
        last = cut
    # Everything is out before the stream ends: no real packet waits behind a lying header.
    assert found == planted
    assert decoder.close() == []
    fakes = sum(len(f) // 4 for f, _ in pieces)
    assert decoder.stats.lying_headers + decoder.stats.bad_checksum >= fakes


def test_one_fake_header_costs_only_itself() -> None:
    """Issue 15's reproduction: ``0F 0C 00 7D`` between status packets, fed as ARIA's 10 Hz stream."""
    before = [status(i) for i in range(3)]
    after = [status(10 + i) for i in range(40)]
    decoder = PacketDecoder()
    found = decoder.feed(b"".join(p.encode() for p in before) + b"\x0f\x0c\x00\x7d")
    for packet in after:
        found += decoder.feed(packet.encode())  # one status per read, as a 10 Hz link delivers them
    assert found == before + after
    assert decoder.stats.lying_headers == 1
    assert decoder.buffered == 0


def test_a_liar_is_held_only_until_the_stream_proves_itself() -> None:
    decoder = PacketDecoder()
    found = decoder.feed(b"\x0f\x0c\x00\x7d")
    for i in range(STREAM_GOES_ON - 1):
        found += decoder.feed(status(i).encode())
    assert found == []  # not yet proven: the header may be a real big packet's
    found += decoder.feed(status(99).encode())
    assert found == [status(i) for i in range(STREAM_GOES_ON - 1)] + [status(99)]


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32), st.integers(0, 4), st.data())
def test_a_real_full_size_packet_with_embedded_runs_is_never_split(
    seed: int, runs: int, data: st.DataObject
) -> None:
    """The big packet arrives slowly while its content (with short valid runs) is scanned behind it."""
    big = Packet(0x0120, big_payload(seed, MAX_PAYLOAD, runs))
    planted = [status(1), big, *(status(2 + i) for i in range(STREAM_GOES_ON))]
    stream = b"".join(p.encode() for p in planted)
    cuts = data.draw(st.lists(st.integers(0, len(stream)), min_size=5, max_size=40))
    decoder = PacketDecoder()
    assert feed_in_chunks(decoder, stream, cuts) == planted
    assert decoder.stats.lying_headers == 0


def test_a_flood_of_fake_headers_then_the_stream_delivers_everything() -> None:
    flood = b"\x0f\x0c\x00\x7d" * 20_000  # 80 000 bytes of fake 32000-byte headers
    after = [status(i) for i in range(STREAM_GOES_ON + 4)]
    stream = flood + b"".join(p.encode() for p in after)
    decoder = PacketDecoder()
    found = feed_in_chunks(decoder, stream, list(range(0, len(stream), 1448)))
    assert found == after
    assert decoder.buffered < MAX_LENGTH


def test_an_over_limit_header_is_named_with_its_length() -> None:
    decoder = PacketDecoder()
    header = b"\x0f\x0c" + (40_000).to_bytes(2, "little") + STATUS.to_bytes(2, "little")
    found = decoder.feed(header + bytes(100) + status(7).encode())
    assert found == [status(7)]
    assert decoder.stats.over_limit == 1
    assert decoder.stats.largest_over_limit == 40_000

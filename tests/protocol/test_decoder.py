"""The incremental decoder (protocol §1.8): any chunking, ARIA's resync cases, counters, memory."""

from __future__ import annotations

import random

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtmu.protocol import MAX_LENGTH, Packet, PacketDecoder, encode_packet
from rtmu.protocol import decoder as decoder_module
from rtmu.protocol.checksum import SpanChecksums, checksum
from rtmu.protocol.decoder import BadPacket, DropStats

GOOD = encode_packet(0x0119, b"\x01")  # the §1.1 getSafeDrive reply: 0F 0C 09 00 19 01 01 00 18
CONNECTED = bytes.fromhex("0F 0C 08 00 05 00 00 05")

packets_st = st.builds(Packet, st.integers(0, 0xFFFF), st.binary(max_size=600))


def mixed_packets(rng: random.Random, count: int) -> list[Packet]:
    """Status-sized packets with the odd empty, medium and full 32000-byte one."""
    out = []
    for i in range(count):
        size = rng.choice([0, 1, 19, 19, 19, 40, 300, 1500]) if i % 50 else rng.choice([31992, 20000])
        out.append(Packet(rng.randrange(0x10000), rng.randbytes(size)))
    return out


def stream_of(packets: list[Packet]) -> bytes:
    return b"".join(p.encode() for p in packets)


def feed_in_chunks(decoder: PacketDecoder, data: bytes, cuts: list[int]) -> list[Packet]:
    out: list[Packet] = []
    last = 0
    for cut in [*sorted(cuts), len(data)]:
        out += decoder.feed(data[last:cut])
        last = cut
    return out


# -- chunking -----------------------------------------------------------------------------


def test_one_byte_at_a_time() -> None:
    packets = mixed_packets(random.Random(1), 120)
    data = stream_of(packets)
    decoder = PacketDecoder()
    out: list[Packet] = []
    for i in range(len(data)):
        out += decoder.feed(data[i : i + 1])
        assert decoder.buffered < MAX_LENGTH
    assert out == packets
    assert decoder.buffered == 0
    assert decoder.stats == DropStats(packets=len(packets))


def test_megabytes_in_one_call() -> None:
    packets = mixed_packets(random.Random(2), 3000)
    data = stream_of(packets)
    assert len(data) > 2_000_000
    decoder = PacketDecoder()
    assert decoder.feed(data) == packets
    assert decoder.buffered == 0
    assert decoder.stats.packets == len(packets)
    assert decoder.stats.dropped == decoder.stats.garbage_bytes == 0


def test_megabytes_split_mid_packet() -> None:
    packets = mixed_packets(random.Random(3), 3000)
    data = stream_of(packets)
    decoder = PacketDecoder()
    out = decoder.feed(data[: len(data) // 2 + 7]) + decoder.feed(data[len(data) // 2 + 7 :])
    assert out == packets


@pytest.mark.parametrize("chunk", [2, 3, 7, 1460, 4096, 65536, 1 << 20])
def test_fixed_chunk_sizes(chunk: int) -> None:
    packets = mixed_packets(random.Random(chunk), 400)
    data = stream_of(packets)
    decoder = PacketDecoder()
    out: list[Packet] = []
    for i in range(0, len(data), chunk):
        out += decoder.feed(data[i : i + chunk])
    assert out == packets


@given(st.lists(packets_st, max_size=25), st.data())
def test_any_chunking_gives_the_same_packets(packets: list[Packet], data: st.DataObject) -> None:
    stream = stream_of(packets)
    cuts = data.draw(st.lists(st.integers(0, len(stream)), max_size=40))
    decoder = PacketDecoder()
    assert feed_in_chunks(decoder, stream, cuts) == packets
    assert decoder.close() == []
    assert decoder.stats == DropStats(packets=len(packets))


def test_accepts_bytearray_and_memoryview_and_empty_feeds() -> None:
    decoder = PacketDecoder()
    assert decoder.feed(b"") == []
    assert decoder.feed(bytearray(GOOD)) == [Packet(0x0119, b"\x01")]
    assert decoder.feed(memoryview(GOOD)[:3]) == []
    assert decoder.feed(memoryview(GOOD)[3:]) == [Packet(0x0119, b"\x01")]


def test_delivered_payloads_are_independent_bytes() -> None:
    decoder = PacketDecoder()
    (packet,) = decoder.feed(GOOD + GOOD[:4])
    decoder.feed(GOOD[4:] + bytes(100))
    assert type(packet.payload) is bytes
    assert packet.payload == b"\x01"


# -- ARIA's resync cases (§1.8) -------------------------------------------------------------


def test_the_documented_live_check() -> None:
    """`00 11 0F 22` + a packet with a bad checksum + `0F 0C 07 00` + a valid packet → one packet."""
    corrupt = bytearray(encode_packet(0x0108, b"\x08\x01\xc8\x00\x00\x00"))
    corrupt[-1] ^= 0xFF
    data = bytes.fromhex("00 11 0F 22") + bytes(corrupt) + bytes.fromhex("0F 0C 07 00") + GOOD
    decoder = PacketDecoder()
    assert decoder.feed(data) == [Packet(0x0119, b"\x01")]
    assert decoder.stats.bad_checksum == 1
    assert decoder.stats.bad_length == 1
    assert decoder.stats.packets == 1
    # the connection is kept: the next packet is decoded as usual
    assert decoder.feed(CONNECTED) == [Packet(5, b"")]


def test_garbage_before_a_packet_is_skipped_and_counted() -> None:
    decoder = PacketDecoder()
    assert decoder.feed(b"\x00\x11\x22garbage" + GOOD) == [Packet(0x0119, b"\x01")]
    assert decoder.stats.garbage_bytes == 10


def test_bad_second_sync_byte() -> None:
    decoder = PacketDecoder()
    assert decoder.feed(b"\x0f\x22\x0f\x0d" + GOOD) == [Packet(0x0119, b"\x01")]
    assert decoder.stats.garbage_bytes == 4


def test_stray_sync1_before_a_packet_does_not_lose_it() -> None:
    """ARIA loses the packet after a stray 0x0F (pitfall 21); we look at the byte again."""
    decoder = PacketDecoder()
    assert decoder.feed(b"\x0f" + GOOD) == [Packet(0x0119, b"\x01")]
    assert decoder.stats.garbage_bytes == 1


@pytest.mark.parametrize("length", [0, 1, 7, MAX_LENGTH + 1, 0xFFFF])
def test_bad_length_is_dropped_and_scanning_resumes_after_the_length_field(length: int) -> None:
    header = b"\x0f\x0c" + length.to_bytes(2, "little")
    decoder = PacketDecoder()
    assert decoder.feed(header + GOOD) == [Packet(0x0119, b"\x01")]
    assert decoder.stats.bad_length == 1
    assert decoder.stats.garbage_bytes == 4


@pytest.mark.parametrize("flip", [4, 5, 6, 8, -2, -1])  # command, payload, checksum
def test_bad_checksum_drops_the_packet_and_keeps_going(flip: int) -> None:
    corrupt = bytearray(encode_packet(0x0200, b"\x01\x02\x03\x04"))
    corrupt[flip] ^= 0x40
    decoder = PacketDecoder()
    assert decoder.feed(bytes(corrupt) + GOOD) == [Packet(0x0119, b"\x01")]
    assert decoder.stats.bad_checksum == 1
    assert decoder.stats.garbage_bytes == len(corrupt)


def test_bad_packets_are_kept_for_tools_when_asked() -> None:
    corrupt = bytearray(GOOD)
    corrupt[-1] ^= 1
    plain = PacketDecoder()
    plain.feed(bytes(corrupt))
    assert plain.bad_packets == []
    keeping = PacketDecoder(keep_bad=True)
    keeping.feed(bytes(corrupt))
    assert keeping.bad_packets == [BadPacket(0x0119, 9, bytes(corrupt))]


def test_false_header_in_garbage_does_not_hide_the_packets_it_covers() -> None:
    """A bogus `0F 0C` claiming 32000 bytes swallows what follows in ARIA; we rescan behind it."""
    bogus = b"\x0f\x0c" + MAX_LENGTH.to_bytes(2, "little") + b"\x00\x01"
    packets = [Packet(300 + i, bytes([i]) * i) for i in range(50)]
    tail = bytes(MAX_LENGTH)  # enough bytes for the bogus header to be complete, then fail
    decoder = PacketDecoder()
    assert decoder.feed(bogus + stream_of(packets) + tail) == packets
    assert decoder.stats.bad_checksum == 1


def test_header_waiting_at_end_of_stream_is_abandoned_on_close() -> None:
    bogus = b"\x0f\x0c" + (5000).to_bytes(2, "little") + b"\x00\x01"
    packets = [Packet(256, b"x"), Packet(257, b"")]
    decoder = PacketDecoder()
    assert decoder.feed(bogus + stream_of(packets)) == []  # still waiting for 5000 bytes
    assert decoder.close() == packets
    assert decoder.stats.truncated_at_close == 1
    assert decoder.stats.garbage_bytes == len(bogus)
    assert decoder.buffered == 0
    assert decoder.feed(GOOD) == [Packet(0x0119, b"\x01")]  # still usable afterwards


def test_close_counts_a_cut_off_packet() -> None:
    decoder = PacketDecoder()
    assert decoder.feed(GOOD + GOOD[:5]) == [Packet(0x0119, b"\x01")]
    assert decoder.close() == []
    assert decoder.stats.truncated_at_close == 1
    assert decoder.stats.garbage_bytes == 5


# -- counters ---------------------------------------------------------------------------------


def test_counters_for_a_hand_built_stream() -> None:
    corrupt = bytearray(encode_packet(0x0300, b"abc"))
    corrupt[7] ^= 1
    data = (
        b"\x01\x02\x03"  # 3 garbage bytes
        + GOOD
        + b"\x0f\x0c\x03\x00"  # bad length
        + bytes(corrupt)  # bad checksum
        + CONNECTED
        + b"\x0f\x0c\x10\x00\x05"  # cut off at the end of the stream
    )
    decoder = PacketDecoder()
    assert decoder.feed(data) == [Packet(0x0119, b"\x01"), Packet(5, b"")]
    decoder.close()
    assert decoder.stats == DropStats(
        garbage_bytes=3 + 4 + len(corrupt) + 5,
        bad_length=1,
        bad_checksum=1,
        truncated_at_close=1,
        packets=2,
    )
    assert decoder.stats.dropped == 3
    assert decoder.stats.as_dict()["bad_checksum"] == 1


# -- hostile input costs linear work -------------------------------------------------------------

FAKE_HEADER = bytes.fromhex("0F 0C 00 7D")
"""Sync plus length 32000: repeated, a fake full-size header every 4 bytes, each failing its checksum."""


@pytest.fixture
def summed_bytes(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """Counts every byte the decoder sums: whole-span checksums and prefix-sum extensions."""
    counter = [0]

    def counting_checksum(data: bytes | bytearray, end: int | None = None, start: int = 0) -> int:
        counter[0] += (len(data) if end is None else end) - start
        return checksum(data, end, start)

    real_extend = SpanChecksums.extend

    def counting_extend(self: SpanChecksums, data: bytes | bytearray, stop: int) -> None:
        counter[0] += max(0, stop - self.stop)
        real_extend(self, data, stop)

    monkeypatch.setattr(decoder_module, "checksum", counting_checksum)
    monkeypatch.setattr(SpanChecksums, "extend", counting_extend)
    return counter


def hostile_stream() -> tuple[bytes, list[Packet]]:
    """200 KB of fake headers with real packets planted inside the spans the fakes claim.

    About 8000 fakes cover each planted packet, so one of them passes its checksum by chance now and
    then (a genuine packet-shaped accident); these payloads were picked so that none does.
    """
    packets = [Packet(0x0200 + i, bytes([i]) * (i * 5 % 300)) for i in range(6)]
    parts = []
    for packet in packets:
        parts += [FAKE_HEADER * 8000, packet.encode()]
    return b"".join(parts) + FAKE_HEADER * 2000, packets


@pytest.mark.parametrize("chunk", [1 << 20, 65536, 1460, 7])
def test_fake_headers_cost_work_linear_in_the_bytes_fed(chunk: int, summed_bytes: list[int]) -> None:
    """Before prefix sums every fake header cost a 32 KB checksum: 8000 times the input."""
    data, planted = hostile_stream()
    decoder = PacketDecoder()
    found = []
    for i in range(0, len(data), chunk):
        found += decoder.feed(data[i : i + chunk])
    found += decoder.close()
    assert found == planted  # still tolerant: packets inside the fake spans are found
    assert decoder.stats.bad_checksum > len(data) // 8
    assert summed_bytes[0] <= 4 * len(data)


def test_one_byte_feeds_of_fake_headers_cost_linear_work(summed_bytes: list[int]) -> None:
    """Each byte completes another fake span: re-summing the buffer per feed would be quadratic."""
    data = FAKE_HEADER * 12000 + GOOD
    decoder = PacketDecoder()
    found = [p for i in range(len(data)) for p in decoder.feed(data[i : i + 1])] + decoder.close()
    assert found == [Packet(0x0119, b"\x01")]
    assert decoder.stats.bad_checksum > 4000
    assert summed_bytes[0] <= 4 * len(data)


def test_kept_bad_packets_hold_at_most_the_bytes_fed() -> None:
    """``keep_bad`` keeps a bad packet only clear of the last one kept, so fakes cannot multiply memory."""
    data = FAKE_HEADER * 40000
    decoder = PacketDecoder(keep_bad=True)
    decoder.feed(data)
    kept = decoder.bad_packets
    assert kept and decoder.stats.bad_checksum > len(kept)
    assert sum(len(bad.raw) for bad in kept) <= len(data)


@given(st.binary(min_size=8, max_size=3000), st.data())
def test_span_checksums_agree_with_the_checksum(data: bytes, draw: st.DataObject) -> None:
    base = draw.draw(st.integers(0, len(data) - 8))
    sums = SpanChecksums()
    stops = sorted(draw.draw(st.lists(st.integers(base + 1, len(data)), min_size=1, max_size=5)))
    sums.start(data, base, stops[0])
    for stop in [*stops[1:], len(data)]:
        sums.extend(data, stop)
    assert sums.stop == len(data)
    for _ in range(20):
        start = draw.draw(st.integers(base, len(data) - 8))
        end = draw.draw(st.integers(start + 6, len(data)))
        assert sums.checksum(data, end, start) == checksum(data, end, start)

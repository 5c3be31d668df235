"""How fast the wire codec turns bytes into packets and typed status updates.

Figures (MB = 10^6 bytes), each against the simple way measured in the same run:

* ``codec.stream_decode_rate`` / ``codec.stream_decode_throughput``: a realistic client stream —
  ``updateNumbers`` status packets (19-byte payload, 27 bytes framed) with one full 32 000-byte
  map/image packet per 200 of them — fed in the chunk sizes a TCP reader gets (single packets,
  MSS-sized segments, 4–64 KB reads). Baseline: ARIA's receiver written the obvious way, a per-byte
  state machine with the per-byte checksum loop.
* ``codec.status_decode_rate``: status packets all the way to typed ``UpdateNumbers`` the way a
  session takes them (``PacketDecoder`` framing and checksum, command number → data name,
  ``decode_payload``), same chunking, in packets per **CPU**-second (``process_time``, best of
  :data:`CPU_RUNS`: it holds on a loaded machine). Baseline: the per-byte receiver plus
  ``FieldReader`` field by field, same measure. Target (issue 28): ≥ 1 M packets per CPU-second.
* ``codec.checksum_throughput``: the checksum of 32 000-byte packets. Baseline: ``checksum_naive``.
  Target: ≥ 200 MB/s.
* ``codec.hostile_garbage_throughput``: ``0F 0C 00 7D`` repeated (a fake 32 000-byte header every 4
  bytes, each failing its checksum) in 1448-byte segments: what one hostile peer can make the decoder
  chew through. Baseline: the same tolerant rescan with each claimed span summed afresh (the decoder
  before it kept prefix sums).
* ``codec.decode.fake_header_flood_mb_s``: the realistic stream above with a lying header
  ``0F 0C 00 7D`` (a fake 32 000-byte packet) before every tenth packet, same chunking; every real
  packet must come out, none held behind a liar. Baseline: the same stream without the liars, so
  the ratio is what looking behind waiting headers costs.
"""

from __future__ import annotations

import random
import time
from collections.abc import Callable
from itertools import cycle

from bench.common import Result, best_time
from rtmu.protocol import MAX_LENGTH, MAX_PAYLOAD, FieldReader, PacketDecoder, encode_packet
from rtmu.protocol.checksum import checksum, checksum_naive
from rtmu.protocol.payloads.base import Side, decode_payload
from rtmu.protocol.payloads.robot import UpdateNumbers

UPDATE_NUMBERS = 0x0108
MAP_DATA = 0x0120
READ_SIZES = (65536, 1448, 27, 4096, 2896, 16384, 27, 1448)
"""What successive ``recv`` calls return on a busy link: whole bursts, segments, single packets."""


class NaiveDecoder:
    """The baseline: ARIA's TCP receiver (§1.8) as a per-byte state machine, per-byte checksum."""

    def __init__(self) -> None:
        self.state = 0
        self.packet = bytearray()
        self.length = 0

    def feed(self, data: bytes) -> list[tuple[int, bytes]]:
        out: list[tuple[int, bytes]] = []
        for byte in data:
            state = self.state
            if state == 0:
                if byte == 0x0F:
                    self.packet = bytearray((byte,))
                    self.state = 1
            elif state == 1:
                if byte == 0x0C:
                    self.packet.append(byte)
                    self.state = 2
                else:
                    self.state = 0
            elif state == 2:
                self.packet.append(byte)
                self.state = 3
            elif state == 3:
                self.packet.append(byte)
                self.length = self.packet[2] | byte << 8
                self.state = 4 if 8 <= self.length <= MAX_LENGTH else 0
            else:
                packet = self.packet
                packet.append(byte)
                if len(packet) == self.length:
                    if checksum_naive(packet[:-2]) == (packet[-2] << 8 | packet[-1]):
                        out.append((packet[4] | packet[5] << 8, bytes(packet[6:-2])))
                    self.state = 0
        return out


def naive_update_numbers(payload: bytes) -> UpdateNumbers:
    """The baseline's typed decode: one FieldReader call per field."""
    r = FieldReader(payload)
    return UpdateNumbers(
        battery=r.byte2("battery") / 10,
        x=r.byte4("x"),
        y=r.byte4("y"),
        th=r.byte2("th"),
        vel=r.byte2("vel"),
        rot_vel=r.byte2("rotVel"),
        lat_vel=r.byte2("latVel"),
        temperature=r.byte("temperature"),
    )


def status_packets(rng: random.Random, count: int) -> list[bytes]:
    out = []
    for _ in range(count):
        status = UpdateNumbers(
            battery=rng.randrange(110, 135) / 10,
            x=rng.randrange(-50_000, 50_000),
            y=rng.randrange(-50_000, 50_000),
            th=rng.randrange(-179, 181),
            vel=rng.randrange(-750, 751),
            rot_vel=rng.randrange(-100, 101),
            lat_vel=0,
            temperature=rng.choice((-128, 25, 31)),
        )
        out.append(encode_packet(UPDATE_NUMBERS, status.encode()))
    return out


def chunked(stream: bytes) -> list[bytes]:
    chunks = []
    pos = 0
    for size in cycle(READ_SIZES):
        if pos >= len(stream):
            return chunks
        chunks.append(stream[pos : pos + size])
        pos += size
    raise AssertionError("unreachable")


def mixed_stream(rng: random.Random, status_count: int, per_big: int = 200) -> tuple[bytes, int]:
    parts = []
    count = 0
    for i, packet in enumerate(status_packets(rng, status_count)):
        parts.append(packet)
        count += 1
        if i % per_big == per_big - 1:
            parts.append(encode_packet(MAP_DATA, rng.randbytes(MAX_PAYLOAD)))
            count += 1
    return b"".join(parts), count


def count_packets(chunks: list[bytes]) -> int:
    decoder = PacketDecoder()
    feed = decoder.feed
    return sum(len(feed(chunk)) for chunk in chunks)


def count_packets_naive(chunks: list[bytes]) -> int:
    decoder = NaiveDecoder()
    return sum(len(decoder.feed(chunk)) for chunk in chunks)


def decode_statuses(chunks: list[bytes]) -> int:
    """A session's path: framed, named by the server's data list, decoded by ``decode_payload``."""
    decoder = PacketDecoder()
    names = {UPDATE_NUMBERS: "updateNumbers"}.get
    count = 0
    for chunk in chunks:
        for command, payload in decoder.feed(chunk):
            name = names(command)
            if name is not None and decode_payload(name, Side.REPLY, payload) is not None:
                count += 1
    return count


def decode_statuses_naive(chunks: list[bytes]) -> int:
    decoder = NaiveDecoder()
    count = 0
    for chunk in chunks:
        for command, payload in decoder.feed(chunk):
            if command == UPDATE_NUMBERS:
                naive_update_numbers(payload)
                count += 1
    return count


def bench_stream() -> list[Result]:
    stream, expected = mixed_stream(random.Random(1), 10_000)
    chunks = chunked(stream)
    assert count_packets(chunks) == expected == count_packets_naive(chunks)
    fast = best_time(lambda: count_packets(chunks))
    slow = best_time(lambda: count_packets_naive(chunks), repeat=3)
    return [
        Result("codec.stream_decode_rate", expected / fast, "packets/s", expected / slow),
        Result("codec.stream_decode_throughput", len(stream) / fast / 1e6, "MB/s", len(stream) / slow / 1e6),
    ]


def bench_status() -> list[Result]:
    packets = status_packets(random.Random(2), 20_000)
    chunks = chunked(b"".join(packets))
    first = UpdateNumbers.decode(packets[0][6:-2])
    assert naive_update_numbers(packets[0][6:-2]) == first
    assert decode_statuses(chunks) == len(packets) == decode_statuses_naive(chunks)
    fast = best_cpu_time(lambda: decode_statuses(chunks))
    slow = best_cpu_time(lambda: decode_statuses_naive(chunks))
    return [Result("codec.status_decode_rate", len(packets) / fast, "packets/s", len(packets) / slow)]


CPU_RUNS = 5


def best_cpu_time(fn: Callable[[], object]) -> float:
    """CPU seconds (this process) of one call of ``fn``: the best of :data:`CPU_RUNS`."""
    best = float("inf")
    for _ in range(CPU_RUNS):
        start = time.process_time()
        fn()
        best = min(best, time.process_time() - start)
    return best


def bench_checksum() -> list[Result]:
    rng = random.Random(3)
    bodies = [encode_packet(MAP_DATA, rng.randbytes(MAX_PAYLOAD))[:-2] for _ in range(8)]
    assert all(checksum(b) == checksum_naive(b) for b in bodies)
    size = sum(len(b) + 2 for b in bodies)  # the whole 32 000-byte packets
    fast = best_time(lambda: [checksum(b) for b in bodies])
    slow = best_time(lambda: [checksum_naive(b) for b in bodies], repeat=3)
    return [Result("codec.checksum_throughput", size / fast / 1e6, "MB/s", size / slow / 1e6)]


def rescan_summing_each_span(chunks: list[bytes]) -> int:
    """The baseline for hostile input: the decoder's tolerant rules, every span's checksum from scratch."""
    buf = bytearray()
    pos = bad = 0
    for chunk in chunks:
        buf += chunk
        while (start := buf.find(b"\x0f\x0c", pos)) >= 0 and len(buf) - start >= 4:
            length = buf[start + 2] | buf[start + 3] << 8
            if not 8 <= length <= MAX_LENGTH:
                pos = start + 4
                continue
            if len(buf) - start < length:
                break
            end = start + length - 2
            if checksum(buf, end, start) != (buf[end] << 8 | buf[end + 1]):
                bad += 1
                pos = start + 2
            else:
                pos = start + length
        if start < 0:
            pos = len(buf)
    return bad


def hostile_bad_checksums(chunks: list[bytes]) -> int:
    decoder = PacketDecoder()
    for chunk in chunks:
        decoder.feed(chunk)
    return decoder.stats.bad_checksum


def bench_hostile() -> list[Result]:
    data = bytes.fromhex("0F 0C 00 7D") * (256 * 1024 // 4)
    chunks = [data[i : i + 1448] for i in range(0, len(data), 1448)]
    assert hostile_bad_checksums(chunks) == rescan_summing_each_span(chunks) > 0
    fast = best_time(lambda: hostile_bad_checksums(chunks), repeat=3)
    slow = best_time(lambda: rescan_summing_each_span(chunks), repeat=1, min_seconds=0)
    return [
        Result("codec.hostile_garbage_throughput", len(data) / fast / 1e6, "MB/s", len(data) / slow / 1e6)
    ]


FAKE_HEADER = bytes.fromhex("0F 0C 00 7D")


def liars_before_every_tenth(stream: bytes) -> bytes:
    """Insert a fake 32 000-byte header before every tenth packet of a clean stream."""
    out = bytearray()
    pos = index = 0
    while pos < len(stream):
        length = stream[pos + 2] | stream[pos + 3] << 8
        if index % 10 == 9:
            out += FAKE_HEADER
        out += stream[pos : pos + length]
        pos += length
        index += 1
    return bytes(out)


def bench_fake_header_flood() -> list[Result]:
    clean, expected = mixed_stream(random.Random(4), 10_000)
    lying = liars_before_every_tenth(clean)
    clean_chunks, lying_chunks = chunked(clean), chunked(lying)
    assert count_packets(lying_chunks) == expected == count_packets(clean_chunks)
    fast = best_time(lambda: count_packets(lying_chunks))
    base = best_time(lambda: count_packets(clean_chunks))
    return [
        Result(
            "codec.decode.fake_header_flood_mb_s", len(lying) / fast / 1e6, "MB/s", len(clean) / base / 1e6
        )
    ]


def run() -> list[Result]:
    return bench_stream() + bench_status() + bench_checksum() + bench_hostile() + bench_fake_header_flood()

"""The status hot path gives exactly what the plain path gives: on real captures and on hostile bytes.

Two fast paths are checked against a reference written the simple way:

* framing: :func:`rtmu.protocol.runs.take_run` (runs of one packet length and command, a status
  stream), one packet at a time and as numpy blocks, against the decoder's general loop alone
  (``_RUN_BELOW`` set to 0 turns runs off) — same packets, same drop counts, whatever the bytes and
  however they are chunked;
* typed decode: ``UpdateNumbers.decode`` (one precompiled unpack, slot setters) and
  :func:`~rtmu.protocol.payloads.base.decode_payload` against a :class:`FieldReader` read field by field
  — same values, and the same error (the same field named) for a payload cut short.
"""

from __future__ import annotations

import copy
import dataclasses
import pickle
import random
from collections import defaultdict

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rtmu.capture import open_capture
from rtmu.capture.base import StreamData
from rtmu.capture.conversation import DecodedPacket
from rtmu.capture.session_decoder import CaptureDecoder
from rtmu.protocol import decoder as decoder_module
from rtmu.protocol import runs
from rtmu.protocol.decoder import PacketDecoder
from rtmu.protocol.errors import FieldUnderrun
from rtmu.protocol.fields import FieldReader
from rtmu.protocol.packet import Packet, encode_packet
from rtmu.protocol.payloads.base import Side, decode_payload
from rtmu.protocol.payloads.robot import TEMPERATURE_UNKNOWN, UpdateNumbers
from testdata import CAPTURES

NUMBERS, STRINGS = 0x0108, 0x0109
CAPTURE_NAMES = sorted(p.name for p in CAPTURES.glob("*.pcap"))


def reference_numbers(payload: bytes) -> UpdateNumbers:
    """The plain way: one FieldReader call per field, the dataclass's own constructor."""
    r = FieldReader(payload)
    return UpdateNumbers(
        battery=r.byte2("battery") / 10,
        x=r.byte4("x"),
        y=r.byte4("y"),
        th=r.byte2("th"),
        vel=r.byte2("vel"),
        rot_vel=r.byte2("rot_vel"),
        lat_vel=r.byte2("lat_vel"),
        temperature=r.byte("temperature"),
    )


MODES = ("general", "one_by_one", "block")
"""The general loop alone (runs off); runs one packet at a time; runs as numpy blocks from 2 packets."""


def frame(stream: bytes, sizes: list[int], *, mode: str) -> tuple[list[Packet], dict[str, int]]:
    """(packets, drop stats) of ``stream`` fed in ``sizes`` chunks, framed the ``mode`` way."""
    with pytest.MonkeyPatch.context() as patch:
        if mode == "general":
            patch.setattr(decoder_module, "_RUN_BELOW", 0)
        elif mode == "one_by_one":
            patch.setattr(runs, "BLOCK_MIN", 1 << 30)
        else:
            patch.setattr(runs, "BLOCK_MIN", 2)
            patch.setattr(runs, "IMPORT_AT", 2)
        decoder = PacketDecoder()
        packets: list[Packet] = []
        pos = 0
        for size in sizes * (len(stream) // max(1, sum(sizes)) + 1):
            if pos >= len(stream):
                break
            packets += decoder.feed(stream[pos : pos + size])
            pos += size
        packets += decoder.feed(stream[pos:])
        packets += decoder.close()
        return packets, decoder.stats.as_dict()


def same_every_way(stream: bytes, sizes: list[int]) -> list[Packet]:
    general, one_by_one, block = (frame(stream, sizes, mode=mode) for mode in MODES)
    assert one_by_one == general
    assert block == general
    return general[0]


def numbers(rng: random.Random) -> UpdateNumbers:
    return UpdateNumbers(
        battery=rng.randrange(-32768, 32768) / 10,
        x=rng.randrange(-(2**31), 2**31),
        y=rng.randrange(-(2**31), 2**31),
        th=rng.randrange(-32768, 32768),
        vel=rng.randrange(-32768, 32768),
        rot_vel=rng.randrange(-32768, 32768),
        lat_vel=rng.randrange(-32768, 32768),
        temperature=rng.randrange(-128, 128),
    )


def status_stream(seed: int, count: int) -> list[bytes]:
    rng = random.Random(seed)
    return [encode_packet(NUMBERS, numbers(rng).encode()) for _ in range(count)]


# -- real captures ---------------------------------------------------------------------------------


@pytest.mark.parametrize("name", CAPTURE_NAMES)
def test_every_capture_stream_frames_the_same_every_way(name: str) -> None:
    streams: dict[tuple[int, object], bytearray] = defaultdict(bytearray)
    for event in open_capture(CAPTURES / name).events():
        if isinstance(event, StreamData):
            streams[(event.flow.id, event.src)] += event.data
    assert streams
    framed = 0
    for stream in streams.values():
        for sizes in ([1 << 20], [1448, 27, 4096, 1]):
            framed += len(same_every_way(bytes(stream), sizes))
    assert framed > 0


def capture_status_payloads() -> list[bytes]:
    out = []
    for name in CAPTURE_NAMES:
        for item in CaptureDecoder().run(open_capture(CAPTURES / name).events()):
            if isinstance(item, DecodedPacket) and item.name == "updateNumbers" and item.direction == "s2c":
                out.append(item.payload)
    return out


def test_every_captured_status_packet_decodes_as_the_field_by_field_reference() -> None:
    payloads = capture_status_payloads()
    assert len(payloads) >= 200  # drive, robotUpdateExample, strings, sensors
    for payload in payloads:
        expected = reference_numbers(payload)
        assert UpdateNumbers.decode(payload) == expected
        assert decode_payload("updateNumbers", Side.REPLY, payload) == expected


# -- hostile bytes ---------------------------------------------------------------------------------


@pytest.mark.parametrize("cut", range(19))
def test_a_status_payload_cut_short_fails_as_the_reference_does(cut: int) -> None:
    payload = numbers(random.Random(cut)).encode()[:cut]
    with pytest.raises(FieldUnderrun) as fast:
        UpdateNumbers.decode(payload)
    with pytest.raises(FieldUnderrun) as plain:
        reference_numbers(payload)
    assert fast.value.field.replace("_", "") == plain.value.field.replace("_", "").lower()


def test_trailing_bytes_after_the_fields_are_ignored_as_the_reference_does() -> None:
    payload = numbers(random.Random(7)).encode() + b"\x01\x02\x03"
    assert UpdateNumbers.decode(payload) == reference_numbers(payload)


def test_a_decoded_status_is_a_frozen_dataclass_like_any_other() -> None:
    decoded = UpdateNumbers.decode(numbers(random.Random(3)).encode())
    built = reference_numbers(decoded.encode())
    assert decoded == built and hash(decoded) == hash(built) and repr(decoded) == repr(built)
    with pytest.raises(AttributeError):
        decoded.x = 1  # type: ignore[misc]
    assert dataclasses.is_dataclass(decoded)
    assert dataclasses.replace(decoded, x=5).x == 5 and dataclasses.replace(decoded, x=5).y == decoded.y
    assert (
        dataclasses.asdict(decoded)
        == decoded.to_fields()
        == {name: getattr(built, name) for name in (f.name for f in dataclasses.fields(built))}
    )
    assert pickle.loads(pickle.dumps(decoded)) == decoded == copy.deepcopy(decoded)
    assert UpdateNumbers(1.0, 1, 2, 3, 4, 5, 6).temperature == TEMPERATURE_UNKNOWN


HOSTILE = st.sampled_from(["flip", "lying_header", "short_same_head", "truncate", "other_command", "noise"])


@settings(max_examples=150, deadline=None)
@given(
    seed=st.integers(0, 2**32),
    damage=st.dictionaries(st.integers(0, 119), HOSTILE, max_size=8),
    sizes=st.lists(st.integers(1, 2000), min_size=1, max_size=5),
)
def test_damaged_status_streams_frame_the_same_every_way(
    seed: int, damage: dict[int, str], sizes: list[int]
) -> None:
    packets = status_stream(seed, 120)
    rng = random.Random(seed)
    for at, kind in sorted(damage.items()):
        packet = bytearray(packets[at])
        if kind == "flip":  # a bit flipped anywhere: header, payload or checksum
            packet[rng.randrange(len(packet))] ^= 1 << rng.randrange(8)
        elif kind == "lying_header":  # a fake 32 000-byte header before it
            packet[:0] = bytes.fromhex("0F 0C 00 7D")
        elif kind == "short_same_head":  # the run's header, then the stream goes on early
            packet = packet[: rng.randrange(4, len(packet))]
        elif kind == "truncate":
            del packet[rng.randrange(1, len(packet)) :]
        elif kind == "other_command":  # same length, another command: a run of its own
            packet = bytearray(encode_packet(STRINGS, bytes(packet[6:-2])))
        else:
            packet[:0] = rng.randbytes(rng.randrange(1, 9))
        packets[at] = bytes(packet)
    same_every_way(b"".join(packets), sizes)


def test_a_clean_status_stream_comes_out_whole_in_order() -> None:
    packets = status_stream(11, 500)
    got = same_every_way(b"".join(packets), [65536, 1448, 27, 4096])
    assert [p.encode() for p in got] == packets


def test_a_bad_checksum_inside_a_run_drops_that_packet_alone() -> None:
    packets = status_stream(12, 50)
    bad = bytearray(packets[20])
    bad[-1] ^= 0xFF
    packets[20] = bytes(bad)
    got, stats = frame(b"".join(packets), [1 << 16], mode="block")
    assert [p.encode() for p in got] == packets[:20] + packets[21:]
    assert stats["bad_checksum"] == 1


@pytest.mark.parametrize("block_min", [2, 1 << 30])
def test_a_clean_run_is_taken_whole_by_the_run_path_itself(block_min: int) -> None:
    packets = status_stream(13, 300)
    stream = b"".join(packets) + packets[0][:10]  # and the start of one more, not yet whole
    found: list[Packet] = []
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(runs, "BLOCK_MIN", block_min)
        patch.setattr(runs, "IMPORT_AT", block_min)
        stopped = runs.take_run(stream, 0, len(stream), len(packets[0]), found)
    assert stopped == len(stream) - 10
    assert [p.encode() for p in found] == packets


def test_blocks_look_at_about_the_run_not_at_the_whole_buffer() -> None:
    """Short runs (a map's lines of one length) never reach the block path; a long run is looked at
    in blocks that grow four times at most past its end (once it looked at the whole buffer behind
    every two-packet run: a map download three times slower)."""
    rng = random.Random(14)
    short_runs = b"".join(
        encode_packet(0x0120, bytes(rng.randrange(1, 256) for _ in range(10 + i % 7))) for i in range(2000)
    )
    long_run = b"".join(status_stream(15, 100))
    looked: list[int] = []
    take_block = runs._take_block

    def counting(buf: bytes, pos: int, count: int, *rest: object) -> int:
        looked.append(count)
        return take_block(buf, pos, count, *rest)  # type: ignore[arg-type]

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(runs, "_take_block", counting)
        patch.setattr(runs, "IMPORT_AT", 2)
        packets = PacketDecoder().feed(short_runs + long_run + short_runs)
    assert len(packets) == 2000 + 100 + 2000
    assert 0 < sum(looked) <= 4 * 100

"""Map payloads and streams (protocol §4.5): captured bytes, assemblers, server encoders, hostile input."""

from __future__ import annotations

import contextlib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from rtmu.protocol.errors import FieldUnderrun, PayloadError, ProtocolError
from rtmu.protocol.payloads import Side, payload_type_for
from rtmu.protocol.payloads.map import (
    Goals,
    GoalsUpdated,
    MapBinaryPacket,
    MapId,
    MapName,
    MapPacketKind,
    MapTextPacket,
    MapUpdated,
    MapWithMaxCategoryPacket,
    MapWithMaxCategoryRequest,
)
from rtmu.protocol.payloads.mapstream import (
    MapBinaryAssembler,
    MapTextAssembler,
    MapTooLarge,
    ReplyAlreadyComplete,
    map_binary_payloads,
    map_text_payloads,
)

# §4.5 captured getMapBinary pieces
LINES_BLOCK = bytes.fromhex(
    "02000000 00000000 00000000 B80B0000 00000000 B80B0000 00000000 B80B0000 D0070000".replace(" ", "")
)
POINTS_BLOCK = bytes.fromhex("05000000 18FCFFFF 0CFEFFFF") + bytes(8 * 4)
END = b"\x00\x00\x00\x00"

HEADER = ["2D-Map", "MinPos: -1000 -500", "MaxPos: 3000 2000", 'Cairn: Goal 100 200 0 "" ICON "Kitchen"']


def captured_binary_stream() -> list[bytes]:
    return [
        *(line.encode() + b"\0" for line in HEADER),
        b"LINES\0",
        LINES_BLOCK,
        END,
        b"DATA\0",
        POINTS_BLOCK,
        END,
        b"",
    ]


# -- single packets ------------------------------------------------------------------


def test_map_name() -> None:
    raw = b"/usr/local/Aria/maps/office.map\0"
    assert MapName.decode(raw) == MapName("/usr/local/Aria/maps/office.map")
    assert MapName.decode(raw).encode() == raw
    assert MapName("").encode() == b"\0"


def test_map_id_captured() -> None:
    raw = bytes.fromhex(
        "00"
        + b"/work/steering/shared/aria-maps/office.map".hex()
        + "0010000000 caa805aa9cbdb941c1260ebacfbf244b f3080000 1525016b".replace(" ", "")
    )
    m = MapId.decode(raw)
    assert m.source_name == "" and m.file_name.endswith("office.map")
    assert m.checksum.hex() == "caa805aa9cbdb941c1260ebacfbf244b"
    assert m.size == 0x08F3 and m.mtime == 0x6B012515
    assert m.encode() == raw
    assert m.to_fields()["checksum"] == "caa805aa9cbdb941c1260ebacfbf244b"


def test_map_id_without_checksum_and_hostile_length() -> None:
    m = MapId("", "x.map", b"", 10, 0)
    assert MapId.decode(m.encode()) == m
    with pytest.raises(PayloadError, match="checksum length"):
        MapId.decode(b"\0x.map\0\xff\xff\xff\x7f")
    with pytest.raises(FieldUnderrun, match="modification time"):
        MapId.decode(m.encode()[:-1])


def test_goals_captured_and_empty() -> None:
    assert Goals.decode(b"Kitchen\0Door\0") == Goals(("Kitchen", "Door"))
    assert Goals(("Kitchen", "Door")).encode() == b"Kitchen\0Door\0"
    assert Goals.decode(b"") == Goals(())
    assert Goals().encode() == b""


def test_empty_broadcasts() -> None:
    assert MapUpdated.decode(b"") == MapUpdated() and MapUpdated().encode() == b""
    assert GoalsUpdated.decode(b"") == GoalsUpdated() and GoalsUpdated().encode() == b""


def test_map_text_packet_kinds() -> None:
    assert MapTextPacket.decode(b"2D-Map\0") == MapTextPacket("2D-Map")
    assert MapTextPacket.decode(b"\0").end_of_map
    assert MapTextPacket.decode(b"").end_of_reply
    for raw in (b"LINES\0", b"\0", b""):
        assert MapTextPacket.decode(raw).encode() == raw


def test_map_binary_packet_kinds_captured() -> None:
    seg = MapBinaryPacket.decode(LINES_BLOCK)
    assert seg.kind is MapPacketKind.SEGMENTS and seg.count == 2
    assert seg.segments.tolist() == [[0, 0, 3000, 0], [3000, 0, 3000, 2000]]
    pts = MapBinaryPacket.decode(POINTS_BLOCK)
    assert pts.kind is MapPacketKind.POINTS and pts.points[0].tolist() == [-1000, -500]
    assert MapBinaryPacket.decode(END).kind is MapPacketKind.BLOCK_END
    assert MapBinaryPacket.decode(b"").kind is MapPacketKind.END_OF_REPLY
    assert MapBinaryPacket.decode(b"DATA\0") == MapBinaryPacket.text_line("DATA")
    assert MapBinaryPacket.decode(b"abc\0").kind is MapPacketKind.TEXT  # 4 bytes, yet not a count
    for raw in captured_binary_stream():
        assert MapBinaryPacket.decode(raw).encode() == raw
    fields = seg.to_fields()
    assert fields["count"] == 2 and fields["segments"][1] == [3000, 0, 3000, 2000]


def test_map_binary_packet_refuses_inconsistent_construction() -> None:
    with pytest.raises(ValueError):
        MapBinaryPacket(MapPacketKind.POINTS, coords=b"\0" * 7)
    with pytest.raises(ValueError):
        MapBinaryPacket(MapPacketKind.TEXT, "x", coords=b"\0" * 8)


def test_max_category_shares_the_layout() -> None:
    assert payload_type_for("getMapWithMaxCategory", Side.REPLY) is MapWithMaxCategoryPacket
    assert MapWithMaxCategoryPacket.decode(LINES_BLOCK).count == 2
    assert MapWithMaxCategoryRequest.decode(b"2D-Map-Ex\0") == MapWithMaxCategoryRequest("2D-Map-Ex")


# -- getMap assembler ---------------------------------------------------------------


def test_text_assembler_full_map() -> None:
    lines = [*HEADER, "LINES", "0 0 3000 0", "DATA", "-1000 -500"]
    a = MapTextAssembler()
    payloads = map_text_payloads(lines)
    assert payloads[-2:] == [b"\0", b""]
    results = [a.feed(p) for p in payloads]
    assert results == [False] * (len(payloads) - 1) + [True]
    r = a.result()
    assert r.has_map and r.lines == lines


def test_text_assembler_no_map() -> None:
    assert map_text_payloads(None) == [b"\0"] == map_text_payloads([])
    a = MapTextAssembler()
    assert a.feed(b"\0") is True
    assert a.result().has_map is False and a.result().lines == []
    with pytest.raises(ReplyAlreadyComplete):
        a.feed(b"")


def test_text_assembler_refuses_text_after_end_and_unfinished_result() -> None:
    a = MapTextAssembler()
    a.feed(b"2D-Map\0")
    with pytest.raises(PayloadError):
        a.result()
    a.feed(b"\0")
    with pytest.raises(PayloadError):
        a.feed(b"more\0")


def test_text_assembler_bounds() -> None:
    a = MapTextAssembler(max_lines=3)
    for p in (b"a\0", b"b\0", b"c\0"):
        a.feed(p)
    with pytest.raises(MapTooLarge):
        a.feed(b"d\0")
    b = MapTextAssembler(max_bytes=10)
    b.feed(b"12345\0")
    with pytest.raises(MapTooLarge):
        b.feed(b"12345\0")


def test_map_text_payloads_refuse_lines_that_break_the_stream() -> None:
    for bad in (["2D-Map", ""], ["a\nb"], ["x" * 40000]):
        with pytest.raises(ValueError):
            map_text_payloads(bad)


# -- getMapBinary assembler -----------------------------------------------------------


def feed_all(a: MapBinaryAssembler, payloads: list[bytes]) -> list[bool]:
    return [a.feed(p) for p in payloads]


def test_binary_assembler_captured_stream() -> None:
    a = MapBinaryAssembler()
    stream = captured_binary_stream()
    assert feed_all(a, stream) == [False] * (len(stream) - 1) + [True]
    r = a.result()
    assert r.has_map and r.header_lines == HEADER
    assert r.segments.dtype == np.int32 and r.segments.shape == (2, 4)
    assert r.points.shape == (5, 2) and r.points[0].tolist() == [-1000, -500]
    assert r.points.flags.writeable


def test_binary_encoder_reproduces_captured_stream() -> None:
    segs = np.array([[0, 0, 3000, 0], [3000, 0, 3000, 2000]])
    pts = np.array([[-1000, -500], [0, 0], [0, 0], [0, 0], [0, 0]])
    assert map_binary_payloads(HEADER, segs, pts) == captured_binary_stream()


def test_binary_no_map() -> None:
    assert map_binary_payloads(None) == [b"\0"]
    a = MapBinaryAssembler()
    assert a.feed(b"\0") is True
    r = a.result()
    assert not r.has_map and r.points.shape == (0, 2) and r.segments.shape == (0, 4)


def test_binary_lines_only_server() -> None:
    segs = np.array([[1, 2, 3, 4]])
    payloads = map_binary_payloads(["2D-Map"], segs, send_points=False)
    assert payloads[-3:] == [b"DATA\0", b"\0", b""]
    a = MapBinaryAssembler()
    assert feed_all(a, payloads)[-1]
    assert a.result().segments.tolist() == [[1, 2, 3, 4]]


def test_binary_no_lines_no_points_like_office_map() -> None:
    payloads = map_binary_payloads(["2D-Map"])
    assert payloads == [b"2D-Map\0", b"DATA\0", END, b""]
    a = MapBinaryAssembler()
    assert feed_all(a, payloads) == [False, False, False, True]


def test_binary_packets_hold_at_most_1000_items() -> None:
    pts = np.arange(2 * 2500, dtype=np.int64).reshape(-1, 2)
    payloads = map_binary_payloads(["2D-Map"], None, pts)
    blocks = payloads[2:-2]
    assert [int.from_bytes(b[:4], "little") for b in blocks] == [1000, 1000, 500]
    assert max(len(b) for b in blocks) == 8004
    a = MapBinaryAssembler()
    feed_all(a, payloads)
    assert np.array_equal(a.result().points, pts)


def test_binary_encoder_rounds_floats_and_refuses_bad_shapes() -> None:
    payloads = map_binary_payloads(["2D-Map"], None, np.array([[1.4, -2.6]]))
    assert payloads[2] == b"\x01\0\0\0" + (1).to_bytes(4, "little") + (-3).to_bytes(4, "little", signed=True)
    with pytest.raises(ValueError):
        map_binary_payloads(["2D-Map"], None, np.zeros((3, 3)))
    with pytest.raises(ValueError):
        map_binary_payloads(["2D-Map"], None, np.array([[2**31, 0]]))


def test_binary_assembler_point_bound() -> None:
    payloads = map_binary_payloads(["2D-Map"], None, np.zeros((1500, 2), dtype=np.int32))
    a = MapBinaryAssembler(max_points=1200)
    with pytest.raises(MapTooLarge):
        feed_all(a, payloads)
    assert a.point_count <= 1200


def test_binary_assembler_segment_and_header_bounds() -> None:
    payloads = map_binary_payloads(["2D-Map"], np.zeros((20, 4), dtype=np.int32), per_packet=10)
    with pytest.raises(MapTooLarge):
        feed_all(MapBinaryAssembler(max_segments=15), payloads)
    with pytest.raises(MapTooLarge):
        feed_all(MapBinaryAssembler(max_header_lines=2), [b"2D-Map\0", b"a\0", b"b\0"])


@pytest.mark.parametrize(
    "bad",
    [
        b"\x05\0\0\0" + bytes(8),  # count 5, one point's bytes
        b"\xff\xff\xff\x7f",  # huge count, nothing behind it
        b"\xff\xff\xff\xff" + bytes(8),  # negative count
        b"\x01\0",  # too short for a count
    ],
)
def test_binary_assembler_refuses_hostile_blocks(bad: bytes) -> None:
    a = MapBinaryAssembler()
    feed_all(a, [b"2D-Map\0", b"DATA\0"])
    with pytest.raises(ProtocolError):
        a.feed(bad)


def test_binary_assembler_protocol_violations() -> None:
    a = MapBinaryAssembler()
    a.feed(b"2D-Map\0")
    with pytest.raises(PayloadError, match="outside"):
        a.feed(POINTS_BLOCK)  # binary data before LINES/DATA
    b = MapBinaryAssembler()
    feed_all(b, [b"2D-Map\0", b"DATA\0"])
    with pytest.raises(PayloadError, match="inside a block"):
        b.feed(b"")  # truncated reply
    c = MapBinaryAssembler()
    feed_all(c, [b"2D-Map\0", b"DATA\0", END])
    with pytest.raises(PayloadError, match="unexpected text"):
        c.feed(b"Cairn: late\0")
    c.feed(b"")
    with pytest.raises(ReplyAlreadyComplete):
        c.feed(b"")


def test_header_lines_that_merely_end_in_a_keyword_stay_text() -> None:
    a = MapBinaryAssembler()
    feed_all(a, [b"2D-Map\0", b"MapInfo: Name=RAW_DATA\0", b"DATA\0", END, b""])
    assert a.result().header_lines == ["2D-Map", "MapInfo: Name=RAW_DATA"]


def test_binary_assembler_accepts_scan_prefixed_sections() -> None:
    a = MapBinaryAssembler()
    stream = [b"2D-Map-Ex\0", b"LINES\0", LINES_BLOCK, END, b"DATA\0", POINTS_BLOCK, END]
    stream += [b"Laser_DATA\0", POINTS_BLOCK, END, b""]
    assert feed_all(a, stream)[-1]
    assert a.result().points.shape == (10, 2)


coords4 = hnp.arrays(np.int32, st.tuples(st.integers(0, 40), st.just(4)))
coords2 = hnp.arrays(np.int32, st.tuples(st.integers(0, 2100), st.just(2)))
lines = st.lists(
    st.text(st.characters(min_codepoint=32, max_codepoint=255), min_size=1, max_size=30), max_size=5
)


@settings(max_examples=60, deadline=None)
@given(lines, coords4, coords2, st.integers(1, 1000))
def test_binary_stream_round_trip(header: list[str], segs: np.ndarray, pts: np.ndarray, per: int) -> None:
    header = ["2D-Map", *header]
    payloads = map_binary_payloads(header, segs, pts, per_packet=per)
    a = MapBinaryAssembler()
    assert feed_all(a, payloads)[-1]
    r = a.result()
    assert r.header_lines == header
    assert np.array_equal(r.segments, segs.reshape(-1, 4)) and np.array_equal(r.points, pts.reshape(-1, 2))
    for p in payloads:
        assert MapBinaryPacket.decode(p).encode() == p


@given(st.binary(max_size=200))
def test_binary_packet_decode_never_crashes(raw: bytes) -> None:
    with contextlib.suppress(ProtocolError):
        MapBinaryPacket.decode(raw)


@given(lines)
def test_text_stream_round_trip(body: list[str]) -> None:
    map_lines = ["2D-Map", *body]
    a = MapTextAssembler()
    assert [a.feed(p) for p in map_text_payloads(map_lines)][-1]
    assert a.result().lines == map_lines


@pytest.mark.parametrize(
    ("name", "cls"),
    [
        ("getMapName", MapName),
        ("getMapId", MapId),
        ("getGoals", Goals),
        ("mapUpdated", MapUpdated),
        ("getMap", MapTextPacket),
        ("getMapBinary", MapBinaryPacket),
    ],
)
def test_registered(name: str, cls: type) -> None:
    assert payload_type_for(name, Side.REPLY) is cls

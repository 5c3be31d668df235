"""The drawings codec (``payloads.drawings``): ARIA's layouts, real captured packets, hostile sizes.

The captures of ARIA 2.9.1's serverDemo hold its data list (which drawings exist, how each is
answered) and the laser and sonar buffers those drawings send; ``getDrawingList`` replies
themselves were not captured, so their bytes are checked against ArServerInfoDrawings' layout
written out here field by field.
"""

from __future__ import annotations

import struct
import time

import pytest

from rtmu.capture import open_capture
from rtmu.capture.conversation import DecodedPacket
from rtmu.capture.session_decoder import CaptureDecoder
from rtmu.protocol.errors import FieldUnderrun, PayloadError
from rtmu.protocol.payloads import Side, payload_type_for
from rtmu.protocol.payloads.drawings import (
    MAX_DRAWINGS,
    MAX_POINTS,
    Drawing,
    DrawingList,
    DrawingListPacket,
    DrawingPoints,
    Shape,
    Visibility,
)
from testdata import CAPTURES

ARIA_DRAWING_REPLY = (
    "See getDrawingList for the information on how this drawing should be drawn, "
    "and the documentation in ArDrawingData for that information means."
)


def _decode(name: str) -> CaptureDecoder:
    decoder = CaptureDecoder()
    for _ in decoder.run(open_capture(CAPTURES / name).events()):
        pass
    return decoder


def test_serverdemo_lists_its_range_devices_as_single_packet_drawings() -> None:
    (session,) = _decode("clientCommandLister-serverDemoMap.pcap").sessions
    dl = session.datalist
    assert dl.entry("getDrawingList").flag_set == {"RETURN_UNTIL_EMPTY"}
    assert dl.entry("getDrawingList").command_group == "SensorInfo"
    drawn = [e.name for e in dl if e.return_description == ARIA_DRAWING_REPLY]
    assert drawn == [
        "sim_lms2xx_1Current",
        "sim_lms2xx_1Cumulative",
        "bumpersCurrent",
        "irsCurrent",
        "sonarCurrent",
    ]
    for name in drawn:
        assert dl.entry(name).flag_set == {"RETURN_SINGLE"}, name


def test_the_captured_laser_and_sonar_buffers_go_through_a_drawing_packet_unchanged() -> None:
    """What getSensorCurrent returned is the buffer the drawing sends: 181 laser points, 24 sonar."""
    seen: dict[str, tuple[tuple[int, int], ...]] = {}
    for packet in CaptureDecoder().run(open_capture(CAPTURES / "sensors.pcap").events()):
        if (
            isinstance(packet, DecodedPacket)
            and packet.name == "getSensorCurrent"
            and packet.direction == "s2c"
        ):
            seen[packet.fields["name"]] = tuple((x, y) for x, y in packet.fields["readings"])
    assert len(seen["sim_lms2xx_1"]) == 181 and len(seen["sonar"]) == 24
    for points in (seen["sim_lms2xx_1"], seen["sonar"]):
        wire = struct.pack("<i", len(points)) + b"".join(struct.pack("<ii", x, y) for x, y in points)
        assert DrawingPoints(points).encode() == wire
        assert DrawingPoints.decode(wire).points == points


def test_a_drawing_list_packet_is_arias_layout_field_by_field() -> None:
    d = Drawing("sonarCurrent", "polyArrows", 0x33CCFF, 200, 70, 200, 0, "DefaultOn")
    wire = b"sonarCurrent\0polyArrows\0" + struct.pack("<iiiIi", 0x33CCFF, 200, 70, 200, 0) + b"DefaultOn\0"
    assert DrawingListPacket(d).encode() == wire
    back = DrawingListPacket.decode(wire).drawing
    assert back == d and back is not None
    assert back.known_shape is Shape.POLY_ARROWS and back.visibility_kind is Visibility.DEFAULT_ON
    assert back.rgb == pytest.approx((0x33 / 255, 0xCC / 255, 1.0))
    assert DrawingListPacket.decode(b"").end_of_reply
    assert payload_type_for("getDrawingList", Side.REPLY) is DrawingListPacket


@pytest.mark.parametrize(
    ("visibility", "shown", "toggle"),
    [
        ("AlwaysOn", True, False),
        ("DefaultOn", True, True),
        ("DefaultOff", False, True),
        ("AlwaysOff", False, False),
        ("", True, True),
        ("<b>Sometimes</b>", True, True),
    ],
)
def test_visibility_says_what_is_shown_at_first_and_what_the_operator_may_change(
    visibility: str, shown: bool, toggle: bool
) -> None:
    d = Drawing("x", "polyDots", 0, 1, 70, 200, 0, visibility)
    assert d.shown_by_default is shown and d.operator_may_toggle is toggle


def test_an_unknown_shape_is_kept_as_text_and_reads_as_unknown() -> None:
    d = Drawing("blob", "polyHexagons", 0, 1, 70, 200, 0, "DefaultOn")
    back = DrawingListPacket.decode(DrawingListPacket(d).encode()).drawing
    assert back is not None and back.shape == "polyHexagons" and back.known_shape is None


def test_a_million_point_drawing_is_refused_at_once_without_allocating() -> None:
    """A count the packet cannot hold is refused before any list is built (32 000-byte packets)."""
    honest_max = DrawingPoints(tuple((i, -i) for i in range(MAX_POINTS)))
    assert len(honest_max.encode()) == 4 + 8 * MAX_POINTS <= 32000 - 8
    assert DrawingPoints.decode(honest_max.encode()) == honest_max
    lying = struct.pack("<i", 1_000_000) + honest_max.encode()[4:]
    started = time.perf_counter()
    with pytest.raises(PayloadError, match="point count claims 1000000"):
        DrawingPoints.decode(lying)
    assert time.perf_counter() - started < 5  # generous: the point is that it does not try
    with pytest.raises(PayloadError, match="negative"):
        DrawingPoints.decode(struct.pack("<i", -5))
    with pytest.raises(FieldUnderrun):
        DrawingPoints.decode(b"\x01\x00")


def test_markup_and_control_characters_in_names_come_through_as_plain_text() -> None:
    d = Drawing("<b>x</b>&amp;_\x1b[2J", "polyDots", 0, 1, 70, 200, 0, "DefaultOn")
    back = DrawingListPacket.decode(DrawingListPacket(d).encode()).drawing
    assert back is not None and back.name == "<b>x</b>&amp;_\x1b[2J"


def test_the_old_list_is_bounded_too() -> None:
    many = DrawingList(tuple(Drawing(f"d{i}", "polyDots", 0, 1, 70, 0, 0) for i in range(MAX_DRAWINGS + 5)))
    assert len(DrawingList.decode(many.encode()).drawings) == MAX_DRAWINGS
    with pytest.raises(PayloadError):
        DrawingList.decode(struct.pack("<i", 10_000_000))

"""Sensor payloads (protocol §4.4): sensor list, per-sensor readings, drawings, <device>Current."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtmu.protocol.errors import FieldUnderrun, PayloadError
from rtmu.protocol.payloads import Side, decode_payload, payload_type_for
from rtmu.protocol.payloads.drawings import Drawing, DrawingList, DrawingListPacket
from rtmu.protocol.payloads.sensors import (
    RangeDeviceCumulative,
    RangeDeviceReadings,
    SensorCumulativeReadings,
    SensorCurrentRequest,
    SensorList,
    SensorReadings,
)

names = st.text(st.characters(min_codepoint=1, max_codepoint=255), max_size=20)
int4 = st.integers(-(2**31), 2**31 - 1)
xy = st.tuples(int4, int4)


def test_sensor_list_captured() -> None:
    raw = b"\x04\x00sim_lms2xx_1\0bumpers\0irs\0sonar\0"
    s = SensorList.decode(raw)
    assert s == SensorList(("sim_lms2xx_1", "bumpers", "irs", "sonar"))
    assert s.encode() == raw
    assert SensorList.decode(b"\x01\x00sonar\0").names == ("sonar",)


def test_sensor_list_empty_payload_means_no_device_list() -> None:
    s = SensorList.decode(b"")
    assert not s.listed and s.names == ()
    assert s.encode() == b""
    assert SensorList(()).encode() == b"\0\0"


def test_sensor_list_hostile_counts() -> None:
    with pytest.raises(PayloadError, match="sensor count"):
        SensorList.decode(b"\xff\x7fsonar\0")
    with pytest.raises(PayloadError, match="negative"):
        SensorList.decode(b"\xff\xffsonar\0")
    with pytest.raises(PayloadError, match="sensor count"):
        SensorList.decode(b"\x02\x00")
    with pytest.raises(FieldUnderrun, match="sensor name"):
        SensorList.decode(b"\x02\x00ab")  # unterminated last name runs to the end; the 2nd is missing


def test_sensor_current_request() -> None:
    assert SensorCurrentRequest(("sonar", "sim_lms2xx_1")).encode() == b"sonar\0sim_lms2xx_1\0"
    assert SensorCurrentRequest.decode(b"sonar\0sim_lms2xx_1\0").names == ("sonar", "sim_lms2xx_1")


def test_sensor_readings_captured() -> None:
    assert SensorReadings.decode(b"\x00\x00sonar\0") == SensorReadings("sonar", ())
    missing = SensorReadings.decode(b"\xff\xffnosuch\0")
    assert missing == SensorReadings("nosuch", (), exists=False)
    assert missing.encode() == b"\xff\xffnosuch\0"
    raw = b"\x02\x00sonar\0" + struct.pack("<iiii", 165, -816, 798, -811)
    r = SensorReadings.decode(raw)
    assert r.readings == ((165, -816), (798, -811))
    assert r.encode() == raw


def test_sensor_readings_hostile_and_truncated() -> None:
    with pytest.raises(PayloadError, match="readings"):
        SensorReadings.decode(b"\xff\x7fsonar\0" + bytes(8))
    with pytest.raises(PayloadError, match="negative"):
        SensorReadings.decode(b"\xfe\xffsonar\0")
    with pytest.raises(FieldUnderrun, match="sensor name"):
        SensorReadings.decode(b"\x00\x00")
    with pytest.raises(FieldUnderrun, match="reading count"):
        SensorReadings.decode(b"\x00")
    with pytest.raises(ValueError):
        SensorReadings("x", ((1, 2),), exists=False).encode()


@given(names, st.lists(xy, max_size=50))
def test_sensor_readings_round_trip(name: str, readings: list[tuple[int, int]]) -> None:
    r = SensorReadings(name, tuple(readings))
    raw = r.encode()
    assert SensorReadings.decode(raw) == r
    assert SensorReadings.decode(raw).encode() == raw


@given(st.lists(names, max_size=10))
def test_sensor_list_round_trip(sensor_names: list[str]) -> None:
    s = SensorList(tuple(sensor_names))
    assert SensorList.decode(s.encode()) == s


def test_cumulative_shares_the_layout() -> None:
    assert payload_type_for("getSensorCumulative", Side.REPLY) is SensorCumulativeReadings
    assert SensorCumulativeReadings.decode(b"\x00\x00sonar\0") == SensorCumulativeReadings("sonar")


def test_range_device_current_captured_and_lookup() -> None:
    assert RangeDeviceReadings.decode(b"\0\0\0\0") == RangeDeviceReadings(())
    raw = struct.pack("<iiiii", 2, 10, -20, 30, -40)
    r = decode_payload("sonarCurrent", Side.REPLY, raw)
    assert r == RangeDeviceReadings(((10, -20), (30, -40)))
    assert r is not None and r.encode() == raw
    assert payload_type_for("sim_lms2xx_1Current", Side.REPLY) is RangeDeviceReadings
    assert payload_type_for("sonarCumulative", Side.REPLY) is RangeDeviceCumulative
    # the exact name still wins over the <device>Current family
    assert payload_type_for("getSensorCurrent", Side.REPLY) is SensorReadings
    with pytest.raises(PayloadError):
        RangeDeviceReadings.decode(b"\xff\xff\xff\x0f")


@given(st.lists(xy, max_size=50))
def test_range_device_round_trip(readings: list[tuple[int, int]]) -> None:
    r = RangeDeviceReadings(tuple(readings))
    assert RangeDeviceReadings.decode(r.encode()) == r


SONAR_DRAWING = Drawing("sonarCurrent", "polyArrows", 0x0033CCFF, 80, 75, 5000, 0x000000FF, "DefaultOn")


def test_drawing_list_packets() -> None:
    raw = (
        b"sonarCurrent\0polyArrows\0"
        + struct.pack("<iiiIi", 0x0033CCFF, 80, 75, 5000, 0x000000FF)
        + b"DefaultOn\0"
    )
    p = DrawingListPacket.decode(raw)
    assert p == DrawingListPacket(SONAR_DRAWING)
    assert p.encode() == raw
    end = DrawingListPacket.decode(b"")
    assert end.end_of_reply and end.encode() == b""
    with pytest.raises(FieldUnderrun, match="visibility"):
        DrawingListPacket.decode(raw[: -len(b"DefaultOn\0")])


drawings = st.builds(Drawing, names, names, int4, int4, int4, st.integers(0, 2**32 - 1), int4, names)


@given(drawings)
def test_drawing_round_trip(drawing: Drawing) -> None:
    p = DrawingListPacket(drawing)
    assert DrawingListPacket.decode(p.encode()) == p


def test_list_drawings_deprecated_form() -> None:
    d = DrawingList((Drawing("sonarCurrent", "polyArrows", 1, 2, 3, 4, 5),))
    raw = d.encode()
    assert raw.startswith(b"\x01\0\0\0sonarCurrent\0") and raw.endswith(struct.pack("<i", 5))
    assert DrawingList.decode(raw) == d
    with pytest.raises(PayloadError, match="drawing count"):
        DrawingList.decode(b"\x00\x00\x01\x00" + raw[4:])


def test_registered() -> None:
    assert payload_type_for("getSensorList", Side.REPLY) is SensorList
    assert payload_type_for("getSensorCurrent", Side.ARGS) is SensorCurrentRequest
    assert payload_type_for("getDrawingList", Side.REPLY) is DrawingListPacket
    assert payload_type_for("sonarCurrent", Side.ARGS) is None

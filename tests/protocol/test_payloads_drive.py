"""Driving payloads (protocol §4.3): the captured ratioDrive bytes, optional lat, jog moves."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtmu.protocol.errors import FieldUnderrun
from rtmu.protocol.fields import format_double, parse_double
from rtmu.protocol.packet import encode_packet
from rtmu.protocol.payloads import Side, payload_type_for
from rtmu.protocol.payloads.drive import (
    MoveDist,
    RatioDrive,
    SafeDrive,
    SetSafeDrive,
    TurnByAngle,
    TurnToHeading,
)

# Doubles that survive ARIA's %g text (six significant digits), as a server would see them.
wire_doubles = st.floats(-1e6, 1e6, allow_nan=False).map(lambda v: parse_double(format_double(v)))


def test_ratio_drive_document_example_packet() -> None:
    payload = RatioDrive(50, 0, 100, 0).encode()
    assert payload == b"50\x000\x00100\x000\x00"
    assert encode_packet(0x0117, payload) == bytes.fromhex(
        "0F0C1300170135300030003130300030 00C24C".replace(" ", "")
    )


def test_ratio_drive_three_fields_as_captured() -> None:
    raw = bytes.fromhex("35 30 00 30 00 31 30 30 00")  # drive-tcponly.pcap: (50, 0, 100), no lat
    r = RatioDrive.decode(raw)
    assert r == RatioDrive(50.0, 0.0, 100.0, None)
    assert r.lat_ratio == 0.0 and r.moving
    assert r.encode() == raw


def test_ratio_drive_four_fields() -> None:
    r = RatioDrive.decode(b"-20\x0015.5\x0080\x00-100\x00")
    assert r == RatioDrive(-20.0, 15.5, 80.0, -100.0)
    assert r.lat_ratio == -100.0


def test_ratio_drive_not_moving() -> None:
    assert not RatioDrive(0, 0, 100).moving
    assert not RatioDrive(50, 10, 0).moving
    assert RatioDrive(0, 0, 100, 5).moving


def test_ratio_drive_missing_throttle_names_the_field() -> None:
    with pytest.raises(FieldUnderrun, match="throttle"):
        RatioDrive.decode(b"50\x000\x00")


@given(wire_doubles, wire_doubles, wire_doubles, st.none() | wire_doubles)
def test_ratio_drive_round_trip(trans: float, rot: float, throttle: float, lat: float | None) -> None:
    r = RatioDrive(trans, rot, throttle, lat)
    raw = r.encode()
    assert RatioDrive.decode(raw) == r
    assert RatioDrive.decode(raw).encode() == raw


def test_safe_drive() -> None:
    assert SetSafeDrive(False).encode() == b"\x00"
    assert SetSafeDrive.decode(b"\x07") == SetSafeDrive(True)  # any non-zero is "safe"
    assert SafeDrive.decode(b"\x01") == SafeDrive(True)  # captured
    assert SafeDrive(True).encode() == b"\x01"
    with pytest.raises(FieldUnderrun, match="safe"):
        SafeDrive.decode(b"")


@pytest.mark.parametrize(
    ("cls", "raw", "value"),
    [(MoveDist, b"300\x00", 300.0), (TurnByAngle, b"90\x00", 90.0), (TurnToHeading, b"-12.25\x00", -12.25)],
)
def test_jog_commands_captured(cls: type, raw: bytes, value: float) -> None:
    p = cls.decode(raw)
    assert p == cls(value)
    assert p.encode() == raw


@pytest.mark.parametrize("cls", [MoveDist, TurnByAngle, TurnToHeading])
def test_jog_commands_need_their_number(cls: type) -> None:
    with pytest.raises(FieldUnderrun):
        cls.decode(b"")


@given(wire_doubles)
def test_jog_round_trip(v: float) -> None:
    for cls in (MoveDist, TurnByAngle, TurnToHeading):
        assert cls.decode(cls(v).encode()) == cls(v)


@pytest.mark.parametrize(
    ("name", "side", "cls"),
    [
        ("ratioDrive", Side.ARGS, RatioDrive),
        ("setSafeDrive", Side.ARGS, SetSafeDrive),
        ("getSafeDrive", Side.REPLY, SafeDrive),
        ("moveDist", Side.ARGS, MoveDist),
        ("turnByAngle", Side.ARGS, TurnByAngle),
        ("turnToHeading", Side.ARGS, TurnToHeading),
    ],
)
def test_registered(name: str, side: Side, cls: type) -> None:
    assert payload_type_for(name, side) is cls

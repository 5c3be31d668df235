"""Robot status payloads (protocol §4.1–4.2): captured bytes, round trips, short packets."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtmu.protocol.errors import FieldUnderrun, PayloadError, ProtocolError
from rtmu.protocol.payloads import Side, payload_type_for
from rtmu.protocol.payloads.robot import (
    ActivityTimeInfo,
    BatteryInfo,
    ModeBusyChanged,
    ModeData,
    ModeDataList,
    ModeInfo,
    PhysicalInfo,
    Update,
    UpdateNumbers,
    UpdateStrings,
    battery_tenths,
)

NUMBERS_CAPTURED = bytes.fromhex("8200 00000000 00000000 0000 0000 0000 0000 80")
NUMBERS_MOBILESIM = bytes.fromhex("8200 00000000 00000000 4dff 0000 0000 0000 81")

texts = st.text(st.characters(min_codepoint=1, max_codepoint=255), max_size=40)
int2 = st.integers(-(2**15), 2**15 - 1)
int4 = st.integers(-(2**31), 2**31 - 1)
numbers = st.builds(
    UpdateNumbers,
    battery=int2.map(lambda t: t / 10),
    x=int4,
    y=int4,
    th=int2,
    vel=int2,
    rot_vel=int2,
    lat_vel=int2,
    temperature=st.integers(-128, 127),
)


def test_update_numbers_captured() -> None:
    n = UpdateNumbers.decode(NUMBERS_CAPTURED)
    assert n == UpdateNumbers(13.0, 0, 0, 0, 0, 0, 0, -128)
    assert not n.temperature_known
    assert n.encode() == NUMBERS_CAPTURED
    m = UpdateNumbers.decode(NUMBERS_MOBILESIM)
    assert m.th == -179 and m.temperature == -127
    assert not m.temperature_known, "MobileSim's -127 means no sensor, not -127 degrees"
    assert UpdateNumbers(13.0, 0, 0, 0, 0, 0, 0, -126).temperature_known
    assert m.encode() == NUMBERS_MOBILESIM


def test_update_numbers_signs_and_units() -> None:
    raw = UpdateNumbers(-1.5, -1234, 5678, 180, -300, 45, -7, 31).encode()
    assert raw[:2] == (-15).to_bytes(2, "little", signed=True)
    assert UpdateNumbers.decode(raw) == UpdateNumbers(-1.5, -1234, 5678, 180, -300, 45, -7, 31)


def test_battery_rounds_half_away_from_zero() -> None:
    assert battery_tenths(12.25) == 123
    assert battery_tenths(-12.25) == -123
    assert battery_tenths(13.0) == 130


@pytest.mark.parametrize("cut", range(19))
def test_update_numbers_truncated_names_the_field(cut: int) -> None:
    with pytest.raises(FieldUnderrun) as info:
        UpdateNumbers.decode(NUMBERS_CAPTURED[:cut])
    expected = ["battery"] * 2 + ["x"] * 4 + ["y"] * 4 + ["th"] * 2
    expected += ["vel"] * 2 + ["rot_vel"] * 2 + ["lat_vel"] * 2 + ["temperature"]
    assert info.value.field == expected[cut]


def test_update_numbers_out_of_range_refused_on_encode() -> None:
    with pytest.raises(ValueError, match="out of range"):
        UpdateNumbers(13.0, 2**31, 0, 0, 0, 0, 0).encode()


@given(numbers)
def test_update_numbers_round_trip(n: UpdateNumbers) -> None:
    raw = n.encode()
    assert len(raw) == 19
    assert UpdateNumbers.decode(raw) == n
    assert UpdateNumbers.decode(raw).encode() == raw


@given(st.binary(min_size=19, max_size=19))
def test_update_numbers_any_19_bytes_round_trip(raw: bytes) -> None:
    assert UpdateNumbers.decode(raw).encode() == raw


def test_update_strings_captured() -> None:
    raw = b"Stopped\0Stop\0Stopped\0"
    s = UpdateStrings.decode(raw)
    assert s == UpdateStrings("Stopped", "Stop", "Stopped")
    assert s.encode() == raw
    jog = b"Moving 300 mm\0Jog\0Moving 300 mm\0"
    assert UpdateStrings.decode(jog).encode() == jog


def test_update_strings_missing_extended_status() -> None:
    with pytest.raises(FieldUnderrun, match="extended status"):
        UpdateStrings.decode(b"Stopped\0Stop\0")


@given(texts, texts, texts)
def test_update_strings_round_trip(a: str, b: str, c: str) -> None:
    s = UpdateStrings(a, b, c)
    assert UpdateStrings.decode(s.encode()) == s


def test_update_captured_32_bytes() -> None:
    raw = b"Stopped\0Stop\0" + NUMBERS_CAPTURED
    assert len(raw) == 32
    u = Update.decode(raw)
    assert u == Update("Stopped", "Stop", UpdateNumbers(13.0, 0, 0, 0, 0, 0, 0, -128))
    assert u.encode() == raw


def test_update_short_numbers_name_the_field() -> None:
    with pytest.raises(FieldUnderrun) as info:
        Update.decode(b"Stopped\0Stop\0" + NUMBERS_CAPTURED[:7])
    assert info.value.field == "y"


@given(texts, texts, numbers)
def test_update_round_trip(status: str, mode: str, n: UpdateNumbers) -> None:
    u = Update(status, mode, n)
    assert Update.decode(u.encode()) == u


def test_battery_info_captured_defaults() -> None:
    raw = bytes.fromhex("31312E35 00 3131 00 00")
    b = BatteryInfo.decode(raw)
    assert b == BatteryInfo(11.5, 11.0, False)
    assert b.encode() == raw
    soc = BatteryInfo(20.0, 5.0, True).encode()
    assert soc == b"20\x005\x00\x01"


def test_battery_info_truncated() -> None:
    # Older servers leave the state-of-charge flag out: their figures are volts.
    assert BatteryInfo.decode(b"11.5\x0011\x00") == BatteryInfo(11.5, 11.0, False)
    with pytest.raises(FieldUnderrun, match="shutdown"):
        BatteryInfo.decode(b"11.5\x00")


def test_physical_info_captured() -> None:
    raw = bytes.fromhex("00 00 9001 FA00 FA00 00")
    p = PhysicalInfo.decode(raw)
    assert p == PhysicalInfo("", "", 400, 250, 250, False)
    assert p.encode() == raw
    dx = PhysicalInfo("Pioneer", "p3dx", 381, 210, 255, False)
    assert PhysicalInfo.decode(dx.encode()) == dx


def test_physical_info_truncated() -> None:
    with pytest.raises(FieldUnderrun, match="length rear"):
        PhysicalInfo.decode(bytes.fromhex("00 00 9001 FA00 FA"))


def test_activity_time_info() -> None:
    assert ActivityTimeInfo.decode(b"\xff\xff\xff\xff") == ActivityTimeInfo(-1)
    assert ActivityTimeInfo(12).encode() == b"\x0c\0\0\0"
    with pytest.raises(FieldUnderrun):
        ActivityTimeInfo.decode(b"\x01")


def test_mode_info_captured() -> None:
    assert ModeInfo.decode(b"stop\0\0\0") == ModeInfo("stop", False, False)
    raw = b"ratioDrive\0\0\0"
    assert ModeInfo.decode(raw).encode() == raw
    assert ModeInfo("jogPositionMode", True, True).encode() == b"jogPositionMode\0\x01\x01"
    with pytest.raises(FieldUnderrun, match="will unlock"):
        ModeInfo.decode(b"stop\0\0")


def test_mode_data_list_captured_layout() -> None:
    entries = (ModeData("ratioDrive", "ratioDrive"), ModeData("stop", "stop"), ModeData("wander", "wander"))
    raw = b"\x03\0\0\0ratioDrive\0ratioDrive\0stop\0stop\0wander\0wander\0"
    assert ModeDataList.decode(raw) == ModeDataList(entries)
    assert ModeDataList(entries).encode() == raw


def test_mode_data_list_hostile_count_refused_cheaply() -> None:
    with pytest.raises(PayloadError, match="mode data count"):
        ModeDataList.decode(b"\xff\xff\xff\xffab\0")


@given(st.lists(st.tuples(texts, texts), max_size=8))
def test_mode_data_list_round_trip(rows: list[tuple[str, str]]) -> None:
    m = ModeDataList(tuple(ModeData(a, b) for a, b in rows))
    assert ModeDataList.decode(m.encode()) == m


def test_mode_busy_changed() -> None:
    assert ModeBusyChanged.decode(b"\x01") == ModeBusyChanged(True)
    assert ModeBusyChanged(False).encode() == b"\x00"


@pytest.mark.parametrize(
    ("name", "cls"),
    [
        ("updateNumbers", UpdateNumbers),
        ("updateStrings", UpdateStrings),
        ("update", Update),
        ("batteryInfo", BatteryInfo),
        ("physicalInfo", PhysicalInfo),
        ("getModeInfo", ModeInfo),
        ("getModeDataList", ModeDataList),
        ("activityTimeInfo", ActivityTimeInfo),
    ],
)
def test_registered_as_replies(name: str, cls: type) -> None:
    assert payload_type_for(name, Side.REPLY) is cls
    assert payload_type_for(name, Side.ARGS) is None


def test_errors_are_protocol_errors() -> None:
    assert issubclass(FieldUnderrun, ProtocolError) and issubclass(PayloadError, ProtocolError)

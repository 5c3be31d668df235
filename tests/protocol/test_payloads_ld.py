"""The LD (ARAM) payloads: round trips, hand-built bytes, and the registry finding them by name."""

from __future__ import annotations

import struct

import pytest

from rtmu.protocol.errors import ProtocolError
from rtmu.protocol.payloads import Side, payload_type_for
from rtmu.protocol.payloads.ld import (
    DataStoreValue,
    DockInfo,
    DockInfoChanged,
    DockState,
    GotoRouteGoal,
    Patrol,
    Routes,
    Say,
    data_store_label,
)
from rtmu.protocol.payloads.sensors import RangeDeviceReadings


def test_dock_info_reads_hand_built_bytes():
    # ubyte state 2 (docked), ubyte forced 1, ubyte2 seconds to shutdown 300 (little-endian)
    raw = bytes([2, 1]) + struct.pack("<H", 300)
    info = DockInfo.decode(raw)
    assert info == DockInfo(DockState.DOCKED, True, 300)
    assert info.state_label == "Docked"
    assert info.encode() == raw


@pytest.mark.parametrize("state", list(DockState))
def test_dock_info_round_trip(state):
    for cls in (DockInfo, DockInfoChanged):
        value = cls(state, False, 0)
        assert cls.decode(value.encode()) == value
        assert len(value.encode()) == 4


def test_dock_info_keeps_an_unknown_state_and_refuses_short_bytes():
    assert DockInfo.decode(bytes([7, 0, 0, 0])).state_label == "state 7"
    with pytest.raises(ProtocolError):
        DockInfo.decode(bytes([1, 0, 5]))


def test_routes_are_names_with_no_count():
    raw = b"Loop\x00Night patrol\x00"
    assert Routes.decode(raw).routes == ("Loop", "Night patrol")
    assert Routes(("Loop", "Night patrol")).encode() == raw
    assert Routes.decode(b"").routes == ()


@pytest.mark.parametrize(
    ("cls", "value"),
    [(Patrol, "Loop"), (GotoRouteGoal, "Kitchen"), (Say, "Hello there"), (DataStoreValue, "87")],
)
def test_one_string_payloads(cls, value):
    raw = value.encode("latin-1") + b"\x00"
    decoded = cls.decode(raw)
    assert decoded == cls(value)
    assert decoded.encode() == raw


def test_laser_scans_decode_as_range_device_readings():
    # byte4 count 2, then byte4 x, byte4 y per point (map mm, signed)
    raw = struct.pack("<i", 2) + struct.pack("<iiii", 1500, -20, -3000, 42)
    cls = payload_type_for("Laser_1Current", Side.REPLY)
    assert cls is RangeDeviceReadings
    assert cls.decode(raw).readings == ((1500, -20), (-3000, 42))
    with pytest.raises(ProtocolError):
        cls.decode(struct.pack("<i", 3) + struct.pack("<ii", 1, 1))  # count beyond the bytes


def test_registry_finds_every_ld_name():
    assert payload_type_for("dockInfo", Side.REPLY) is DockInfo
    assert payload_type_for("dockInfoChanged", Side.REPLY) is DockInfoChanged
    assert payload_type_for("getRoutes", Side.REPLY) is Routes
    assert payload_type_for("patrol", Side.ARGS) is Patrol
    assert payload_type_for("say", Side.ARGS) is Say
    assert payload_type_for("DataStore_WiFi_Quality", Side.REPLY) is DataStoreValue
    assert data_store_label("DataStore_WiFi_Quality") == "WiFi Quality"
    assert data_store_label("DataStore_LaserLocalizationScore") == "Laser Localization Score"

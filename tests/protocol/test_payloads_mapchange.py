"""processMapChanges, its verdict, mapChangesInProgress: ARIA's byte layout, series, bounds, hostile input."""

from __future__ import annotations

import struct

import numpy as np
import pytest

from rtmu.protocol.errors import PayloadError, ProtocolError
from rtmu.protocol.payloads import Side, payload_type_for
from rtmu.protocol.payloads.configcare import (
    ConfigDefaults,
    ConfigDefaultsRequest,
    SetConfigParam,
    SetConfigParamReply,
)
from rtmu.protocol.payloads.map import MapId
from rtmu.protocol.payloads.mapchange import (
    CONTINUES,
    NULL_MAP_ID,
    ChangeCommand,
    ChangeData,
    CoordChange,
    FileLine,
    FileLineGroup,
    LineChange,
    LineSetChange,
    MapChangeAssembler,
    MapChangePacket,
    MapChangeReply,
    MapChangeSet,
    MapChangesInProgress,
    change_packets,
)


def s(text: str) -> bytes:
    return text.encode("latin-1") + b"\x00"


def i4(value: int) -> bytes:
    return struct.pack("<i", value)


def map_id_bytes(source: str, name: str, checksum: bytes, size: int, mtime: int) -> bytes:
    return s(source) + s(name) + struct.pack("<I", len(checksum)) + checksum + struct.pack("<Ii", size, mtime)


NULLS = map_id_bytes("", "", b"", 0, -1) * 2
CONT = struct.pack("<H", 1) + NULLS
OFFICE = MapId("", "office.map", bytes(range(16)), 2291, 1795237141)
GOAL = 'Cairn: Goal 1000 2000 0.000000 "" ICON "Kitchen"'


def test_a_continue_packet_of_objects_is_laid_out_as_arias_writer_lays_it() -> None:
    raw = (
        struct.pack("<H", 1)
        + map_id_bytes("", "office.map", bytes(range(16)), 2291, 1795237141)
        + map_id_bytes("", "", b"", 0, -1)
        + bytes([4, 1]) + s("")  # objects, additions, default scan
        + i4(-1) + i4(2)  # no info index, two groups
        + i4(0) + i4(12) + s(GOAL)
        + i4(1) + i4(13) + s("RouteInfo: Route r1") + i4(14) + s("RouteInfo: Task t")
    )  # fmt: skip
    packet = MapChangePacket.decode(raw)
    assert packet.command is ChangeCommand.CONTINUE
    assert packet.orig_id == OFFICE and packet.new_id == NULL_MAP_ID and packet.new_id.is_null
    assert (packet.data, packet.change, packet.scan_type, packet.info_index, packet.total) == (
        ChangeData.OBJECTS, LineChange.ADDITIONS, "", -1, 2,
    )  # fmt: skip
    assert packet.groups == (
        FileLineGroup(FileLine(12, GOAL)),
        FileLineGroup(FileLine(13, "RouteInfo: Route r1"), (FileLine(14, "RouteInfo: Task t"),)),
    )
    assert packet.encode() == raw
    assert payload_type_for("processMapChanges", Side.ARGS) is MapChangePacket


def test_start_finish_and_cancel_carry_only_the_command_and_two_ids() -> None:
    for command in (ChangeCommand.START, ChangeCommand.FINISH, ChangeCommand.CANCEL):
        raw = struct.pack("<H", command) + map_id_bytes("", "", b"", 0, -1) * 2
        assert MapChangePacket(command).encode() == raw
        assert MapChangePacket.decode(raw) == MapChangePacket(command)


def test_points_and_segments_come_in_runs_of_a_thousand_and_five_hundred() -> None:
    points = np.arange(2500 * 2, dtype=np.int32).reshape(-1, 2)
    segments = -np.arange(501 * 4, dtype=np.int32).reshape(-1, 4)
    changes = MapChangeSet(
        coord_sets=(
            CoordChange(ChangeData.POINTS, LineChange.ADDITIONS, points),
            CoordChange(ChangeData.LINES, LineChange.DELETIONS, segments),
        )
    )
    packets = change_packets(changes)
    kinds = [(p.command.name, p.data.name, p.change.name, p.total, p.count) for p in packets]
    assert kinds == [
        ("START", "NONE", "ADDITIONS", -1, 0),
        ("CONTINUE", "LINES", "DELETIONS", 501, 500),  # deletions go first, as ARIA sends them
        ("CONTINUE", "LINES", "DELETIONS", CONTINUES, 1),
        ("CONTINUE", "POINTS", "ADDITIONS", 2500, 1000),
        ("CONTINUE", "POINTS", "ADDITIONS", CONTINUES, 1000),
        ("CONTINUE", "POINTS", "ADDITIONS", CONTINUES, 500),
        ("FINISH", "NONE", "ADDITIONS", -1, 0),
    ]
    second = packets[4].encode()
    head = CONT + bytes([5, 1]) + s("")
    assert second[: len(head)] == head and second[len(head) : len(head) + 4] == i4(-1)
    assert struct.unpack_from("<ii", second, len(head) + 4) == (2000, 2001)
    assembler = MapChangeAssembler()
    done = [assembler.feed(MapChangePacket.decode(p.encode())) for p in packets]
    assert done == [False] * 6 + [True]
    result = assembler.result()
    assert np.array_equal(result.coords(ChangeData.POINTS, LineChange.ADDITIONS), points)
    assert np.array_equal(result.coords(ChangeData.LINES, LineChange.DELETIONS), segments)


def test_a_guarded_series_carries_the_guard_on_every_packet_but_the_start() -> None:
    changes = MapChangeSet(
        (LineSetChange(ChangeData.OBJECTS, LineChange.ADDITIONS, (FileLineGroup(FileLine(3, GOAL)),)),)
    )
    packets = change_packets(changes, OFFICE)
    assert packets[0].orig_id == packets[0].new_id == NULL_MAP_ID
    assert all(p.orig_id == OFFICE and p.new_id == OFFICE for p in packets[1:])
    assert [p.command for p in packets] == [ChangeCommand.START, ChangeCommand.CONTINUE, ChangeCommand.FINISH]


def test_many_objects_spread_over_packets_that_each_fit() -> None:
    groups = tuple(
        FileLineGroup(FileLine(i, f'Cairn: Goal {i} 0 0.000000 "" ICON "g{i}"')) for i in range(5000)
    )
    changes = MapChangeSet((LineSetChange(ChangeData.OBJECTS, LineChange.ADDITIONS, groups),))
    packets = change_packets(changes)
    assert len(packets) > 6
    assert all(len(p.encode()) <= 32000 - 8 for p in packets)
    assert [p.total for p in packets[1:-1]] == [5000] + [CONTINUES] * (len(packets) - 3)
    assembler = MapChangeAssembler()
    for p in packets:
        assembler.feed(MapChangePacket.decode(p.encode()))
    assert assembler.result().lines(ChangeData.OBJECTS, LineChange.ADDITIONS) == [
        g.parent.text for g in groups
    ]


def test_the_verdict_and_the_progress_broadcast() -> None:
    assert MapChangeReply.decode(b"\x0a\x00").accepted
    assert not MapChangeReply.decode(b"\x00\x00").accepted
    assert not MapChangeReply.decode(b"\x07\x00").accepted  # neither 10 nor 0: not applied
    assert MapChangesInProgress.decode(b"\x01").in_progress
    assert not MapChangesInProgress.decode(b"\x00").in_progress
    with pytest.raises(ProtocolError):
        MapChangeReply.decode(b"\x0a")


@pytest.mark.parametrize(
    ("raw", "why"),
    [
        (struct.pack("<H", 4) + map_id_bytes("", "", b"", 0, -1) * 2, "unknown change command"),
        (CONT + bytes([7, 1]) + s(""), "data type"),
        (CONT + bytes([4, 2]) + s(""), "change type"),
        (
            CONT + bytes([4, 1]) + s("") + i4(-1) + i4(0),
            "at least one",
        ),
        (
            CONT + bytes([4, 1]) + s("")
            + i4(-1) + i4(1) + i4(-1) + i4(3) + s("x"),
            "continued",
        ),
        (
            CONT + bytes([4, 1]) + s("")
            + i4(-1) + i4(1) + i4(100_000) + i4(3) + s("x"),
            "child lines",
        ),
        (
            CONT + bytes([5, 1]) + s("") + i4(3) + b"\x01\x02",
            "whole number",
        ),
        (
            CONT + bytes([5, 1]) + s("")
            + i4(2000) + b"\x00" * 8 * 1001,
            "up to 1000",
        ),
        (struct.pack("<H", 0) + s("") + s("m") + struct.pack("<I", 100_000) + b"xx", "checksum"),
    ],
)  # fmt: skip
def test_malformed_packets_are_refused_naming_what_is_wrong(raw: bytes, why: str) -> None:
    with pytest.raises(ProtocolError, match=why):
        MapChangePacket.decode(raw)


def _packet(data: ChangeData, total: int, count: int) -> MapChangePacket:
    width = 2 if data is ChangeData.POINTS else 4
    coords = np.zeros((count, width), np.int32).tobytes()
    return MapChangePacket(ChangeCommand.CONTINUE, data=data, total=total, coords=coords)


@pytest.mark.parametrize(
    ("series", "why"),
    [
        ([MapChangePacket(ChangeCommand.CONTINUE)], "starts with a start"),
        ([MapChangePacket(ChangeCommand.START)] * 2, "second start"),
        ([MapChangePacket(ChangeCommand.START), _packet(ChangeData.POINTS, 5, 3)], "ARIA reads 5"),
        (
            [MapChangePacket(ChangeCommand.START), _packet(ChangeData.POINTS, CONTINUES, 3)],
            "continues nothing",
        ),
        (
            [MapChangePacket(ChangeCommand.START), _packet(ChangeData.POINTS, 1001, 1000),
             _packet(ChangeData.LINES, 1, 1)],
            "still due",
        ),
        (
            [MapChangePacket(ChangeCommand.START), _packet(ChangeData.POINTS, 1001, 1000),
             MapChangePacket(ChangeCommand.FINISH)],
            "missing",
        ),
    ],
)  # fmt: skip
def test_a_series_that_breaks_its_own_counts_is_refused(series: list[MapChangePacket], why: str) -> None:
    assembler = MapChangeAssembler()
    with pytest.raises(PayloadError, match=why):
        for packet in series:
            assembler.feed(packet)


def test_a_series_is_bounded_in_packets_lines_and_points() -> None:
    few = MapChangeAssembler(max_packets=3)
    few.feed(MapChangePacket(ChangeCommand.START))
    few.feed(MapChangePacket(ChangeCommand.CONTINUE))
    few.feed(MapChangePacket(ChangeCommand.CONTINUE))
    with pytest.raises(PayloadError, match="more than 3 packets"):
        few.feed(MapChangePacket(ChangeCommand.CONTINUE))
    lines = MapChangeAssembler(max_groups=10)
    lines.feed(MapChangePacket(ChangeCommand.START))
    groups = tuple(FileLineGroup(FileLine(i, GOAL)) for i in range(11))
    with pytest.raises(PayloadError, match="more than 10 lines"):
        lines.feed(MapChangePacket(ChangeCommand.CONTINUE, data=ChangeData.OBJECTS, total=11, groups=groups))
    points = MapChangeAssembler(max_coords=1500)
    points.feed(MapChangePacket(ChangeCommand.START))
    points.feed(_packet(ChangeData.POINTS, 2000, 1000))
    with pytest.raises(PayloadError, match="more than 1500"):
        points.feed(_packet(ChangeData.POINTS, CONTINUES, 1000))


def test_a_cancelled_series_is_finished_and_says_so() -> None:
    assembler = MapChangeAssembler()
    assembler.feed(MapChangePacket(ChangeCommand.START))
    assert assembler.feed(MapChangePacket(ChangeCommand.CANCEL))
    assert assembler.cancelled and assembler.result().empty


def test_config_care_payloads() -> None:
    assert ConfigDefaultsRequest("").encode() == b""  # all sections: no argument, as ARIA's client asks
    assert ConfigDefaultsRequest("Teleop").encode() == s("Teleop")
    defaults = ConfigDefaults.decode(
        s("Section") + s("Teleop") + s("Timeout") + s("2") + s("Section") + s("B")
    )
    assert defaults.by_section() == [("Teleop", "Timeout", "2")]
    assert ConfigDefaults.decode(b"").by_section() == []
    assert SetConfigParam.of({"Teleop": {"Timeout": "1"}}).encode() == s("Section") + s("Teleop") + s(
        "Timeout"
    ) + s("1")
    ok = SetConfigParamReply.decode(s("Teleop") + s(""))
    assert (ok.section, ok.error, ok.accepted) == ("Teleop", "", True)
    refused = SetConfigParamReply.decode(s("Teleop") + s("Teleop/Timeout: 99 is above the maximum of 60"))
    assert not refused.accepted and refused.error.startswith("Teleop/Timeout")
    prevented = SetConfigParamReply.decode(s("Changes prevented while the robot is being serviced"))
    assert (prevented.section, prevented.accepted) == ("", False)
    assert "serviced" in prevented.error

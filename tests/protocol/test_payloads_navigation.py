"""Navigation payloads (protocol §4.8, ARNL): hand-built bytes, optional fields, hostile counts."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtmu.protocol.errors import FieldUnderrun, PayloadError, ProtocolError
from rtmu.protocol.payloads import Side, payload_type_for
from rtmu.protocol.payloads.navigation import (
    LOC_SCORE_FULL,
    MAX_PATH_POINTS,
    Dock,
    GoalName,
    GotoGoal,
    GotoPose,
    Home,
    LocalizationState,
    LocalizeToPose,
    LocState,
    PathPlannerStatus,
    PlannedPath,
    TourGoals,
)

int4 = st.integers(-(2**31), 2**31 - 1)


def test_goto_goal_is_one_string() -> None:
    assert GotoGoal.decode(b"Goal 5\x00") == GotoGoal("Goal 5")
    assert GotoGoal("Kitchen").encode() == b"Kitchen\x00"
    assert GotoGoal.decode(b"Door") == GotoGoal("Door")  # like ARIA, the payload's end ends a string
    with pytest.raises(FieldUnderrun, match="goal name"):
        GotoGoal.decode(b"")


def test_goto_pose_heading_is_four_bytes_as_arnl_reads_it() -> None:
    raw = struct.pack("<iii", 3000, -1200, -90)
    pose = GotoPose.decode(raw)
    assert pose == GotoPose(3000, -1200, -90)
    assert pose.encode() == raw


def test_goto_pose_without_heading_remembers_none() -> None:
    raw = struct.pack("<ii", 3000, 0)
    assert GotoPose.decode(raw) == GotoPose(3000, 0, None)
    assert GotoPose(3000, 0).encode() == raw


def test_goto_pose_reads_the_documented_two_byte_heading_and_writes_it_back() -> None:
    raw = struct.pack("<iih", 10, 20, -45)
    pose = GotoPose.decode(raw)
    assert (pose.th, pose.short_th) == (-45, True)
    assert pose.encode() == raw


def test_goto_pose_needs_x_and_y() -> None:
    with pytest.raises(FieldUnderrun, match="y"):
        GotoPose.decode(struct.pack("<i", 1) + b"\x01")


@given(int4, int4, st.none() | int4)
def test_goto_pose_round_trip(x: int, y: int, th: int | None) -> None:
    p = GotoPose(x, y, th)
    assert GotoPose.decode(p.encode()) == p


@pytest.mark.parametrize("cls", [Home, TourGoals])
def test_empty_commands(cls: type) -> None:
    assert cls().encode() == b""
    assert cls.decode(b"") == cls()


def test_dock_with_and_without_the_forced_byte() -> None:
    assert Dock.decode(b"") == Dock(None)
    assert Dock().encode() == b""
    assert Dock.decode(b"\x01") == Dock(1)
    assert Dock(0).encode() == b"\x00"


def test_localize_to_pose_with_optional_spreads() -> None:
    raw = struct.pack("<iii", 1530, -4770, 45)
    assert LocalizeToPose.decode(raw) == LocalizeToPose(1530, -4770, 45)
    assert LocalizeToPose(1530, -4770, 45).encode() == raw
    full = raw + struct.pack("<II", 300, 15)
    assert LocalizeToPose.decode(full) == LocalizeToPose(1530, -4770, 45, 300, 15)
    assert LocalizeToPose(1530, -4770, 45, 300, 15).encode() == full
    assert LocalizeToPose.decode(raw + struct.pack("<I", 300)).th_spread is None
    with pytest.raises(FieldUnderrun, match="heading"):
        LocalizeToPose.decode(struct.pack("<ii", 1, 2))


def test_loc_state_reads_hand_built_bytes() -> None:
    raw = bytes([2]) + struct.pack("<H", 125)  # lost, score 0.125
    state = LocState.decode(raw)
    assert state == LocState(LocalizationState.LOST, 125)
    assert state.state_label == "Lost"
    assert state.score_fraction == pytest.approx(0.125)
    assert state.encode() == raw
    assert LocState(0, LOC_SCORE_FULL).score_fraction == 1.0
    assert LocState.decode(bytes([9, 0, 0])).state_label == "state 9"
    with pytest.raises(FieldUnderrun, match="score"):
        LocState.decode(b"\x00\x01")


def test_planned_path_layout() -> None:
    raw = struct.pack("<h", 2) + struct.pack("<iiii", 1500, -20, -3000, 42)
    path = PlannedPath.decode(raw)
    assert path.points == ((1500, -20), (-3000, 42))
    assert path.encode() == raw
    assert PlannedPath.decode(struct.pack("<h", 0)) == PlannedPath(())
    assert PlannedPath().encode() == b"\x00\x00"


def test_planned_path_refuses_lying_counts_and_oversized_paths() -> None:
    with pytest.raises(PayloadError):
        PlannedPath.decode(struct.pack("<h", 3) + struct.pack("<ii", 1, 1))
    with pytest.raises(PayloadError):
        PlannedPath.decode(struct.pack("<h", -1))
    with pytest.raises(ProtocolError):
        PlannedPath.decode(b"")
    with pytest.raises(PayloadError):
        PlannedPath(((0, 0),) * (MAX_PATH_POINTS + 1)).encode()
    assert len(PlannedPath(((0, 0),) * MAX_PATH_POINTS).encode()) == 2 + 8 * MAX_PATH_POINTS


@pytest.mark.parametrize(("cls", "text"), [(PathPlannerStatus, "Planning path"), (GoalName, "Kitchen")])
def test_one_string_replies(cls: type, text: str) -> None:
    raw = text.encode() + b"\x00"
    assert cls.decode(raw) == cls(text)
    assert cls(text).encode() == raw


@pytest.mark.parametrize(
    ("name", "side", "cls"),
    [
        ("gotoGoal", Side.ARGS, GotoGoal),
        ("gotoPose", Side.ARGS, GotoPose),
        ("home", Side.ARGS, Home),
        ("tourGoals", Side.ARGS, TourGoals),
        ("dock", Side.ARGS, Dock),
        ("localizeToPose", Side.ARGS, LocalizeToPose),
        ("getLocState", Side.REPLY, LocState),
        ("getPath", Side.REPLY, PlannedPath),
        ("pathPlannerStatus", Side.REPLY, PathPlannerStatus),
        ("goalName", Side.REPLY, GoalName),
    ],
)
def test_registered(name: str, side: Side, cls: type) -> None:
    assert payload_type_for(name, side) is cls

"""The rules of "why won't it move?" on plain facts (no I/O): precedence, our own side, safe drive's
geometry, the watchdog, words, and reading replies of unknown layout."""

from __future__ import annotations

from rtmu.client.why import diagnose, moved, unexplained
from rtmu.client.why_gather import ld_entries, limits_from, split_fields
from rtmu.client.why_safe_drive import nearest
from rtmu.client.why_still import StillWhileHeld
from rtmu.client.why_values import (
    ARIA_LIMITER_DEFAULTS,
    Cause,
    Facts,
    Footprint,
    Motion,
    Obstacle,
    OurSide,
    SafeDriveLimits,
)
from rtmu.protocol.datalist import DataEntry
from rtmu.protocol.payloads.robot import ModeInfo
from rtmu.values.state import LinkLevel

ALL = frozenset({"ratioDrive", "stop", "setSafeDrive", "undock"})
P3DX = Footprint(425, 210, 301)
LIMITS = SafeDriveLimits(150, 150, 50, "test")


def causes(facts: Facts, motion: Motion | None = None, navigate: bool = False) -> list[Cause]:
    return [r.cause for r in diagnose(facts, motion, navigate=navigate).reasons]


def test_nothing_found_is_exit_0_and_says_so() -> None:
    answer = diagnose(Facts(offers=ALL))
    assert answer.can_move and answer.exit_code == 0 and "Nothing RTMU can read" in answer.sentence()


def test_our_side_comes_first_and_each_state_is_told() -> None:
    facts = Facts(offers=frozenset(), ours=OurSide(link=LinkLevel.STALE))
    assert causes(facts)[:2] == [Cause.LINK, Cause.NO_DRIVE]
    assert causes(Facts(offers=ALL, ours=OurSide(keys_blocked=True))) == [Cause.LEASE]
    replay = diagnose(Facts(offers=ALL, ours=OurSide(replay=True, keys_blocked=True)))
    assert replay.exit_code == 34 and "replay" in replay.sentence()
    assert causes(Facts(offers=ALL, ours=OurSide(lease_ended="lapsed"))) == [Cause.LEASE]
    assert causes(Facts(offers=ALL, ours=OurSide(lease_ended="released"))) == []
    noted = diagnose(Facts(offers=ALL, ours=OurSide(guardian="it could not log in")))
    assert noted.can_move and "guardian" in noted.notes[0]


def test_no_stop_is_loud_and_last_but_exits_20_alone() -> None:
    answer = diagnose(Facts(offers=frozenset({"ratioDrive"}), status="Stalled"))
    assert [r.cause for r in answer.reasons] == [Cause.STALLED, Cause.NO_STOP]
    assert answer.reasons[1].loud and answer.exit_code == 26
    assert diagnose(Facts(offers=frozenset({"ratioDrive"}))).exit_code == 20


def test_the_estop_is_named_only_while_pressed() -> None:
    assert causes(Facts(offers=ALL, status="EStop pressed")) == [Cause.ESTOP]
    assert causes(Facts(offers=ALL, extended_status="Driving\nE-Stop engaged")) == [Cause.ESTOP]
    assert causes(Facts(offers=ALL, status="EStop relieved")) == []
    assert causes(Facts(offers=ALL, status="Motors are disabled")) == [Cause.MOTORS]


def test_a_lock_is_told_with_the_right_way_to_ask() -> None:
    locked = Facts(offers=ALL, mode_info=ModeInfo("Goto", True, True))
    reason = diagnose(locked).reasons[0]
    assert reason.fix is not None and reason.fix.sends == "stop"  # another mode: a stop asks
    stop_locked = Facts(offers=ALL, mode_info=ModeInfo("stop", True, True))
    reason = diagnose(stop_locked).reasons[0]
    assert reason.fix is not None and reason.fix.sends == "ratioDrive"  # the stop mode itself: a drive asks
    for_good = diagnose(Facts(offers=ALL, mode_info=ModeInfo("stop", True, False))).reasons[0]
    assert for_good.fix is None and "will not unlock" in for_good.problem


def test_docked_wins_over_the_docks_own_lock() -> None:
    facts = Facts(offers=ALL, status="Docked", mode_info=ModeInfo("dock", True, True))
    answer = diagnose(facts)
    assert [r.cause for r in answer.reasons] == [Cause.DOCKED]
    assert answer.reasons[0].fix is not None and answer.reasons[0].fix.key == "undock"


def test_the_watchdog_counts_only_when_shorter_than_two_resends() -> None:
    assert causes(Facts(offers=ALL, teleop_timeout=0.15)) == [Cause.WATCHDOG]
    assert causes(Facts(offers=ALL, teleop_timeout=0.0)) == []  # 0: off
    assert causes(Facts(offers=ALL, teleop_timeout=0.2)) == []
    assert causes(Facts(offers=ALL, teleop_timeout=2.0)) == []


def test_lost_counts_only_for_navigation() -> None:
    facts = Facts(offers=ALL, loc_state="Lost")
    assert causes(facts) == [] and causes(facts, navigate=True) == [Cause.LOST]
    (note,) = diagnose(facts).notes  # said, not counted: the operator may mean to navigate next
    assert note.startswith("driving by hand is not held back, but navigation is: the robot is lost")
    assert diagnose(facts, navigate=True).notes == () and diagnose(Facts(offers=ALL)).notes == ()


def safe(*obstacles: Obstacle, on: bool = True) -> Facts:
    return Facts(offers=ALL, safe_drive=on, footprint=P3DX, limits=LIMITS, obstacles=obstacles)


def test_safe_drive_matters_only_the_way_the_robot_is_asked_to_go() -> None:
    ahead = Obstacle(210 + 80, 0, "laser")
    assert causes(safe(ahead)) == [Cause.SAFE_DRIVE]
    assert causes(safe(ahead), Motion(50, 0)) == [Cause.SAFE_DRIVE]
    assert causes(safe(ahead), Motion(-50, 0)) == []  # backing away
    assert causes(safe(ahead), Motion(0, 40)) == []  # turning on the spot is never held back
    assert causes(safe(ahead, on=False)) == []
    assert causes(safe(Obstacle(255.5 + 150, 0, "laser"))) == []  # beyond the distance (from half its length)
    assert causes(safe(Obstacle(255.5 + 149, 0, "laser"))) == [Cause.SAFE_DRIVE]
    assert causes(safe(Obstacle(290, 300, "sonar"))) == []  # beside the path, not in it
    behind = diagnose(safe(Obstacle(-(255.5 + 20), -100, "sonar")), Motion(-50, 0)).reasons[0]
    assert "276 mm behind its centre (100 mm to the right)" in behind.problem and "= 406 mm" in behind.problem
    assert "forwards: that way is clear" in behind.advice


def test_the_reading_named_is_the_nearest_and_the_most_central() -> None:
    hit = nearest(
        (Obstacle(300, -200, "a"), Obstacle(300, 10, "b"), Obstacle(400, 0, "c")), P3DX, LIMITS, True
    )
    assert hit is not None and hit[0].source == "b" and hit[1] == 300 - 255.5  # ARIA: from half the length


def test_moved_reads_speed_or_a_pose_change_beyond_rounding() -> None:
    assert not moved((0, 0, 0), (5, 5, 1), False)
    assert moved((0, 0, 0), (0, 20, 0), False)
    assert moved((0, 0, 179), (0, 0, -177), False)  # 4° across ±180
    assert not moved((0, 0, 179), (0, 0, -180), False)
    assert moved((0, 0, 0), (0, 0, 0), True)


def test_a_drive_nothing_explains_is_unexplained_even_with_a_no_stop_warning() -> None:
    answer = unexplained(diagnose(Facts(offers=frozenset({"ratioDrive"}))))
    assert [r.cause for r in answer.reasons] == [Cause.UNEXPLAINED, Cause.NO_STOP] and answer.exit_code == 39
    explained = unexplained(diagnose(Facts(offers=ALL, status="Stalled")))
    assert explained.exit_code == 26


def test_a_drive_inside_arias_dead_zone_is_its_own_cause_not_unexplained() -> None:
    """ArActionRatioInput ignores up to ±10 % translation and under ±5 % rotation: the request is why."""
    answer = unexplained(diagnose(Facts(offers=ALL), Motion(10, 4.9)))
    assert [r.cause for r in answer.reasons] == [Cause.DEAD_ZONE] and answer.exit_code == 35
    assert "dead zone" in answer.sentence() and "more than 10 %" in answer.sentence()
    assert causes(Facts(offers=ALL), Motion(-10, 0)) == [Cause.DEAD_ZONE]
    assert causes(Facts(offers=ALL), Motion(11, 0)) == []
    assert causes(Facts(offers=ALL), Motion(0, 5)) == []
    assert causes(Facts(offers=ALL), Motion(0, 0)) == [], "nothing asked for: no dead zone"
    assert causes(Facts(offers=ALL)) == [], "rtmu why asks about no drive in particular"
    assert causes(Facts(offers=frozenset({"stop"})), Motion(5, 0)) == [Cause.NO_DRIVE], "may not drive at all"


def test_replies_of_unknown_layout_are_read_only_where_safe() -> None:
    assert split_fields(b"") == ()
    assert split_fields(b"Fault A\x00Fault B\x00") == ("Fault A", "Fault B")
    assert split_fields(b"\x01") == ("1",) and split_fields(b"\xff\xff") == ("-1",)
    assert split_fields(b"\x1b[2J\x00") == ()  # not printable: shown as hex only
    assert split_fields(b"abc") == ()  # no terminator: not a string
    assert len(split_fields(b"x\x00" * 10_000)) == 64


def test_safe_drive_limits_come_from_the_server_or_are_said_to_be_arias_defaults() -> None:
    assert limits_from(None) is ARIA_LIMITER_DEFAULTS and "ARIA's defaults" in ARIA_LIMITER_DEFAULTS.source


def test_the_ld_reads_are_the_listed_safety_data_only() -> None:
    names = [
        "getFaults",
        "acknowledgeFault",
        "enableMotors",
        "queryMotors",
        "DockInfoState",
        "DataStore_Front_EstopCount",
        "DataStore_WiFi_Quality",
    ]
    entries = [DataEntry(i + 256, n) for i, n in enumerate(names)]
    chosen = [e.name for e in ld_entries(entries)]
    assert chosen == ["getFaults", "queryMotors", "DataStore_Front_EstopCount", "DockInfoState"]


def test_the_windows_hint_comes_once_after_a_second_of_held_stillness() -> None:
    hint = StillWhileHeld()
    assert [hint.update(t, True, False) for t in (0.0, 0.5, 0.99)] == [False, False, False]
    assert hint.update(1.0, True, False) is True and hint.update(2.0, True, False) is False  # once
    assert hint.update(2.1, True, True) is False  # it moves: a new still spell counts afresh
    assert hint.update(2.2, True, False) is False and hint.update(3.2, True, False) is True
    assert hint.update(3.3, False, False) is False and hint.update(9.0, False, False) is False  # released

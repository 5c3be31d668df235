"""ARNL's words read as navigation phases, and the session's NavFeed built from them (no sockets)."""

from __future__ import annotations

from dataclasses import replace

import pytest

from rtmu.base.notices import Kind, Level, Notice
from rtmu.client.call_values import Packet
from rtmu.client.detached import DetachedContext
from rtmu.client.nav_session import NavFeed
from rtmu.client.nav_status import MAX_TEXT, path_remaining, read_status
from rtmu.protocol.payloads.navigation import LocState, PlannedPath
from rtmu.values.state import NavOutcome, RobotState


@pytest.mark.parametrize(
    ("status", "mode", "phase", "target", "sentence"),
    [
        ("Going to Lab B", "Goto", NavOutcome.GOING, "Lab B", ""),
        ("Going to point", "Goto", NavOutcome.GOING, "point", ""),
        ("Going to dock at Charger", "dock", NavOutcome.GOING, "dock at Charger", ""),
        ("Driving into dock", "dock", NavOutcome.GOING, "dock", ""),
        ("Returning home", "Goto", NavOutcome.GOING, "home", ""),
        ("Touring to Room 101", "Goto", NavOutcome.GOING, "Room 101", ""),
        ("Arrived at Lab B", "Goto", NavOutcome.ARRIVED, "Lab B", "Arrived at Lab B"),
        ("Returned home", "Goto", NavOutcome.ARRIVED, "home", "Returned home"),
        ("Docked", "dock", NavOutcome.DOCKED, "dock", "Docked"),
        (
            "Failed to get to Lab B because robot lost",
            "Goto",
            NavOutcome.FAILED,
            "Lab B",
            "Failed to get to Lab B because the robot is lost",
        ),
        (
            "Failed to get to Lab B (path blocked)",
            "Goto",
            NavOutcome.FAILED,
            "Lab B",
            "Failed to get to Lab B because path blocked",
        ),
        ("Failed to get home because robot lost", "Goto", NavOutcome.FAILED, "home", None),
        ("Failed dock", "dock", NavOutcome.FAILED, "dock", "Failed dock"),
        ("Stopped", "stop", NavOutcome.NONE, "", ""),
        ("Going to the kitchen", "ratioDrive", NavOutcome.NONE, "", ""),  # not a navigation mode
    ],
)
def test_arnl_words(status: str, mode: str, phase: NavOutcome, target: str, sentence: str | None) -> None:
    r = read_status(status, mode)
    assert (r.phase, r.target) == (phase, target)
    if sentence is not None:
        assert r.sentence() == sentence


def test_server_text_is_bounded_and_the_distance_follows_the_path() -> None:
    assert len(read_status("Arrived at " + "x" * 5000).text) == MAX_TEXT
    assert path_remaining(0, 0, ()) is None
    assert path_remaining(0, 0, ((3000, 4000), (3000, 5000))) == pytest.approx(6000)


class Rec:
    def __init__(self) -> None:
        self.ctx = DetachedContext()
        self.changes = self.ctx.changes
        self.notices = self.ctx.notices

    def feed(self) -> NavFeed:
        return NavFeed(self.ctx)


def test_outcomes_publish_and_notify_once_but_history_is_silent() -> None:
    rec = Rec()
    feed = rec.feed()
    robot = RobotState(status="Arrived at Lab A", mode_name="Goto")
    feed.robot_changed(robot)  # what happened before we connected: kept, not announced
    assert feed.state.outcome is NavOutcome.ARRIVED and rec.notices == []
    flips: list[bool] = []
    feed.changed = lambda: flips.append(feed.navigating)
    feed.robot_changed(replace(robot, status="Going to Lab B"))
    assert feed.state.navigating and feed.state.target == "Lab B" and flips == [True]
    assert feed.state.outcome is NavOutcome.NONE
    feed.on_path(Packet("getPath", PlannedPath(((0, 0), (3000, 4000))).encode(), 0.0))
    feed.robot_changed(replace(robot, status="Going to Lab B", x=0.0, y=0.0))
    assert feed.state.remaining_mm == pytest.approx(5000)
    feed.robot_changed(replace(robot, status="Failed to get to Lab B because robot lost"))
    assert not feed.state.navigating and feed.state.path == () and flips == [True, False]
    assert (feed.state.outcome, feed.state.reason) == (NavOutcome.FAILED, "the robot is lost")
    assert rec.notices == [
        Notice(Kind.NAVIGATION, Level.WARNING, "Failed to get to Lab B because the robot is lost")
    ]
    feed.robot_changed(replace(robot, status="Failed to get to Lab B because robot lost", x=5.0))
    assert len(rec.notices) == 1  # the same words again are no news


def test_a_stop_while_navigating_is_a_cancel_without_a_notice() -> None:
    rec = Rec()
    feed = rec.feed()
    feed.robot_changed(RobotState(status="Going to point", mode_name="Goto"))
    feed.robot_changed(RobotState(status="Stopped", mode_name="stop"))
    assert feed.state.outcome is NavOutcome.CANCELLED and not feed.state.navigating
    assert rec.notices == []


def test_localization_state_and_a_lost_robot_notice() -> None:
    rec = Rec()
    feed = rec.feed()
    feed.on_loc_state(Packet("getLocState", LocState(0, 950).encode(), 0.0))
    assert (feed.state.loc_state, feed.state.loc_score) == ("Good", 0.95)
    feed.on_loc_state(Packet("getLocState", LocState(2, 80).encode(), 0.0))
    assert feed.state.loc_state == "Lost"
    assert [n.kind for n in rec.notices] == [Kind.NAVIGATION]

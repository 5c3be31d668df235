"""The roster contract the fleet builds on: a direct list is added at once, in order, and never twice."""

from __future__ import annotations

import pytest

from rtmu.client.roster import DirectRoster, RobotAdded, RobotEndpoint, RosterEvent


def test_direct_roster_adds_every_robot_in_order() -> None:
    robots = [RobotEndpoint("alpha", "127.0.0.1", 7272), RobotEndpoint("beta", "127.0.0.1", 7273)]
    heard: list[RosterEvent] = []
    DirectRoster(robots).start(heard.append)
    assert heard == [RobotAdded(robots[0]), RobotAdded(robots[1])]


def test_direct_roster_refuses_two_robots_of_one_name() -> None:
    with pytest.raises(ValueError, match="unique"):
        DirectRoster([RobotEndpoint("a", "h", 1), RobotEndpoint("a", "h", 2)])


def test_closed_direct_roster_emits_nothing() -> None:
    roster = DirectRoster([RobotEndpoint("a", "h", 1)])
    roster.close()
    heard: list[RosterEvent] = []
    roster.start(heard.append)
    assert heard == []

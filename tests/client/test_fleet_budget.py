"""A fleet connects a bounded number of its robots: the rest are listed and connected on demand.

The rules (``fleet.budget``) on plain values, then a real fleet of three simulated robots kept to
two connections: selecting the listed third connects it and lets go of the idle robot used least
recently; a robot that leaves the roster makes room for a listed one; a navigating robot is never
let go (its mission would end with it).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from rtmu.client.roster import DirectRoster, RobotEndpoint, RobotRemoved
from rtmu.client.session import SessionConfig
from rtmu.fleet.budget import to_connect, to_let_go
from rtmu.fleet.sessions import Fleet, RobotSession, robot_profile
from rtmu.package_data import project_map
from rtmu.settings.store import Profile
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.multi import SimFleetThreads, fleet_configs
from rtmu.values.intents import GotoGoal

from .uiqueue import UiQueue

OFFICE = project_map("office.map")


def test_the_first_listed_robots_fill_the_budget_in_list_order() -> None:
    assert to_connect(["a", "b", "c", "d"], [], 2) == ["a", "b"]
    assert to_connect(["a", "b", "c", "d"], ["b"], 3) == ["a", "c"]
    assert to_connect(["a", "b"], ["a", "b"], 2) == []
    assert to_connect(["a", "b", "c"], ["x", "y", "z"], 2) == []  # over the budget already: none more


def test_the_least_recently_used_robot_not_kept_is_let_go() -> None:
    used = {"a": 3.0, "b": 1.0, "c": 2.0, "d": 0.0}
    keep = {"d"}  # e.g. navigating
    gone = to_let_go(list(used), 2, keep=lambda s: s in keep, last_used=used.__getitem__)
    assert gone == ["b", "c"]
    assert to_let_go(list(used), 4, keep=lambda s: False, last_used=used.__getitem__) == []
    assert to_let_go(["a", "b"], 0, keep=lambda s: True, last_used=used.__getitem__) == []  # all kept


@contextmanager
def three_robots_two_connected() -> Iterator[tuple[Fleet, UiQueue, DirectRoster, list[SimThread]]]:
    ui = UiQueue()
    fleet = Fleet(connect_at_most=2)
    with SimFleetThreads(fleet_configs(SimConfig(port=0, camera=False, map_path=OFFICE), 3)) as sims:
        roster = DirectRoster([RobotEndpoint(n, "127.0.0.1", p) for n, p in sims.endpoints()])

        def make(endpoint: RobotEndpoint) -> RobotSession:
            profile = robot_profile(Profile("fleet"), endpoint)
            return RobotSession(fleet.operator, post=ui.post, config=SessionConfig(fetch_map=False),
                                profile=profile)  # fmt: skip

        try:
            fleet.follow(roster, make)
            ui.wait_for(lambda: len(fleet) == 2 and all(s.controller.connected for s in fleet), timeout=15)
            yield fleet, ui, roster, sims.sims
        finally:
            fleet.close()


def logins(sim: SimThread) -> int:
    return len(sim.call(lambda: list(sim.server.sessions)))


def test_a_listed_robot_connects_when_selected_and_the_idle_one_used_least_recently_is_let_go() -> None:
    with three_robots_two_connected() as (fleet, ui, _roster, sims):
        assert [e.name for e in fleet.listed.value] == ["robot1", "robot2", "robot3"]
        assert [s.name for s in fleet] == ["robot1", "robot2"] and logins(sims[2]) == 0
        third = fleet.select_named("robot3")
        assert fleet.selected.value is third
        ui.wait_for(lambda: third.controller.connected, timeout=15)
        assert [s.name for s in fleet] == ["robot1", "robot3"], "robot2 (never selected) was not let go"
        ui.wait_for(lambda: logins(sims[1]) == 0, timeout=10)
        assert sims[1].call(lambda: list(sims[1].server.stop_log)) == [], "an idle robot let go was stopped"
        fleet.select_named("robot2")  # back again: now robot1, used least recently, goes
        ui.wait_for(lambda: [s.name for s in fleet] == ["robot3", "robot2"], timeout=10)


def test_a_navigating_robot_is_never_let_go() -> None:
    with three_robots_two_connected() as (fleet, ui, _roster, _sims):
        second = fleet.named("robot2")
        assert second is not None
        fleet.select(second)
        ui.wait_for(lambda: "Lab A" in second.state.navigation.value.goals, timeout=15)
        second.controller.ask(GotoGoal("Lab A"))  # the server drives it there on its own
        ui.wait_for(lambda: second.controller.navigating, timeout=15)
        fleet.select(fleet.named("robot1"))  # type: ignore[arg-type]  # robot2 used less recently now
        fleet.select_named("robot3")
        assert {s.name for s in fleet} == {"robot2", "robot3"}, "the navigating robot was let go"


def test_a_robot_that_leaves_makes_room_for_a_listed_one() -> None:
    with three_robots_two_connected() as (fleet, ui, _roster, sims):
        fleet.on_roster(RobotRemoved("robot1", "switched off"))
        assert [e.name for e in fleet.listed.value] == ["robot2", "robot3"]
        ui.wait_for(lambda: [s.name for s in fleet] == ["robot2", "robot3"], timeout=10)
        ui.wait_for(lambda: all(s.controller.connected for s in fleet) and logins(sims[2]) >= 1, timeout=15)

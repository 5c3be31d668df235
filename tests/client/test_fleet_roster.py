"""A fleet built from a roster's events, against three simulated robots over loopback (``sim.multi``).

Added robots get a session each that connects; a removed robot is stopped and
closed while the others carry on; a lost roster stops every robot with ONE notice;
selecting another robot first stops the one selected before; one robot's lost link
leaves the others connected and drivable.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager

from patience import PATIENCE
from rtmu.client.roster import (
    DirectRoster,
    Emit,
    RobotAdded,
    RobotEndpoint,
    RobotRemoved,
    RosterEvent,
    RosterLost,
    RosterRestored,
)
from rtmu.client.session import SessionConfig
from rtmu.fleet.sessions import Fleet, RobotSession, robot_profile
from rtmu.model.observables import Phase
from rtmu.package_data import project_map
from rtmu.settings.store import Profile
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.multi import SimFleetThreads, fleet_configs

from .uiqueue import UiQueue

ARENA = project_map("arena.map")


class HandRoster:
    """A direct roster whose later events the test sends itself (as a central server would)."""

    def __init__(self, endpoints: list[RobotEndpoint]) -> None:
        self.direct = DirectRoster(endpoints)
        self.emit: Emit | None = None
        self.closed = False

    def start(self, emit: Emit) -> None:
        self.emit = emit
        self.direct.start(emit)

    def close(self) -> None:
        self.closed = True
        self.direct.close()

    def send(self, event: RosterEvent) -> None:
        assert self.emit is not None
        self.emit(event)


@contextmanager
def three_robots() -> Iterator[tuple[Fleet, UiQueue, HandRoster, list[SimThread], list[str]]]:
    ui = UiQueue()
    fleet = Fleet()
    heard: list[str] = []
    with SimFleetThreads(fleet_configs(SimConfig(port=0, map_path=ARENA), 3)) as sims:
        roster = HandRoster([RobotEndpoint(n, "127.0.0.1", p) for n, p in sims.endpoints()])

        def make(endpoint: RobotEndpoint) -> RobotSession:
            profile = robot_profile(Profile("fleet"), endpoint)
            return RobotSession(fleet.operator, post=ui.post, config=SessionConfig(fetch_map=False),
                                profile=profile)  # fmt: skip

        try:
            fleet.follow(roster, make, heard.append)
            ui.wait_for(lambda: all(s.state.connection.value.connected for s in fleet), timeout=15)
            yield fleet, ui, roster, sims.sims, heard
        finally:
            fleet.close()


def mode(sim: SimThread) -> str:
    return str(sim.call(lambda: sim.server.robot.mode_name))


def drives(sim: SimThread) -> int:
    return int(sim.call(lambda: sim.server.robot.ratio_drives_received))


def hold(ui: UiQueue, session: RobotSession, seconds: float, *more: RobotSession) -> None:
    """Hold forward on ``session`` (and ``more``) as the window does: press, then renew at 10 Hz."""
    for s in (session, *more):
        s.controller.press("forward")
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        for s in (session, *more):
            s.controller.tick()
        ui.drain()
        time.sleep(0.1)


def wait_mode(sim: SimThread, wanted: str, within: float = 5.0) -> None:
    """Generous for a loaded machine; a test that means *our* stop also checks the watchdog did not act."""
    deadline = time.monotonic() + within * PATIENCE
    while mode(sim) != wanted:
        assert time.monotonic() < deadline, f"the robot's mode is {mode(sim)!r}, not {wanted!r}"
        time.sleep(0.02)


def test_every_robot_of_the_roster_gets_a_connected_session_and_the_first_is_selected() -> None:
    with three_robots() as (fleet, _ui, _roster, sims, heard):
        assert [s.name for s in fleet] == ["robot1", "robot2", "robot3"]
        assert fleet.selected.value is fleet.named("robot1")
        poses = {(round(s.snapshot().x), round(s.snapshot().y)) for s in sims}
        assert len(poses) == 3, "the simulated robots start on top of each other"
        assert heard == []


def test_selecting_another_robot_stops_the_one_driven_and_the_new_one_waits() -> None:
    with three_robots() as (fleet, ui, _roster, sims, _heard):
        first, second = fleet.named("robot1"), fleet.named("robot2")
        assert first is not None and second is not None
        hold(ui, first, 0.6)
        assert mode(sims[0]) == "ratioDrive"
        fleet.select(second)
        wait_mode(sims[0], "stop")  # half the watchdog: our stop, not ARIA's
        assert first.controller.held == frozenset()
        first.controller.press("forward")  # the old key's auto-repeat: still blocked there
        assert first.controller.held == frozenset()
        assert drives(sims[1]) == 0, "the newly selected robot moved without a fresh press"
        hold(ui, second, 0.5)
        assert mode(sims[1]) == "ratioDrive"
        second.controller.release("forward")


def test_a_removed_robot_is_stopped_and_closed_and_the_rest_carry_on() -> None:
    with three_robots() as (fleet, ui, roster, sims, heard):
        gone = fleet.named("robot2")
        assert gone is not None
        hold(ui, gone, 0.6)
        assert mode(sims[1]) == "ratioDrive"
        roster.send(RobotRemoved("robot2", "switched off"))
        wait_mode(sims[1], "stop")
        assert gone.closed and [s.name for s in fleet] == ["robot1", "robot3"]
        assert heard == ["robot2 left the fleet: switched off"]
        third = fleet.named("robot3")
        assert third is not None
        hold(ui, third, 0.5)
        assert mode(sims[2]) == "ratioDrive", "another robot no longer drives"
        third.controller.release("forward")


def test_a_lost_roster_stops_every_robot_with_one_notice() -> None:
    with three_robots() as (fleet, ui, roster, sims, heard):
        sessions = list(fleet)
        hold(ui, sessions[0], 0.5, *sessions[1:])
        assert [mode(sim) for sim in sims] == ["ratioDrive"] * 3
        roster.send(RosterLost("central server closed the connection"))
        roster.send(RosterLost("again"))
        for sim in sims:
            wait_mode(sim, "stop")
        assert all(sim.snapshot().watchdog_stops == 0 for sim in sims), "stopped by the watchdog, not by us"
        assert len(heard) == 1 and "central server closed the connection" in heard[0]
        assert len(fleet) == 0 and fleet.selected.value is None
        assert all(s.closed for s in sessions)


def test_a_restored_roster_brings_its_robots_back_still_until_pressed() -> None:
    with three_robots() as (fleet, ui, roster, sims, heard):
        first = fleet.named("robot1")
        assert first is not None
        hold(ui, first, 0.5)
        roster.send(RosterLost("central server closed the connection", retrying=True))
        wait_mode(sims[0], "stop")
        assert "trying to reach it again" in heard[0]
        roster.send(RobotAdded(RobotEndpoint("robot1", "127.0.0.1", sims[0].port)))  # before the restore
        assert len(fleet) == 0, "a robot announced while the roster is lost is not taken"
        roster.send(RosterRestored())
        roster.send(RosterRestored())
        assert heard[1:] == ["The robot list is back: reconnecting to its robots (press again to drive)"]
        for sim in sims:
            roster.send(RobotAdded(RobotEndpoint(f"robot{sims.index(sim) + 1}", "127.0.0.1", sim.port)))
        ui.wait_for(lambda: len(fleet) == 3 and all(s.state.connection.value.connected for s in fleet), 15)
        again = fleet.named("robot1")
        assert again is not None and again is not first and fleet.selected.value is again
        drives_before = drives(sims[0])
        end = time.monotonic() + 0.5
        while time.monotonic() < end:  # the new sessions run, the operator presses nothing
            ui.drain()
            time.sleep(0.02)
        assert drives(sims[0]) == drives_before and mode(sims[0]) == "stop", "nothing drives unpressed"
        hold(ui, again, 0.5)
        assert mode(sims[0]) == "ratioDrive"
        again.controller.release("forward")


def test_one_robots_lost_link_leaves_the_others_connected_and_drivable() -> None:
    with three_robots() as (fleet, ui, _roster, sims, _heard):
        sims[0].kill()
        first = fleet.named("robot1")
        assert first is not None
        ui.wait_for(lambda: first.state.connection.value.phase is not Phase.CONNECTED, timeout=10)
        others = [fleet.named("robot2"), fleet.named("robot3")]
        assert all(s is not None and s.state.connection.value.connected for s in others)
        fleet.select(others[1])  # type: ignore[arg-type]
        hold(ui, others[1], 0.5)  # type: ignore[arg-type]
        assert mode(sims[2]) == "ratioDrive"
        assert drives(sims[1]) == 0

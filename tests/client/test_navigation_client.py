"""The window's side of navigation end to end: runner, session, model and controller over loopback.

Against the navigating simulator (on a fast manual clock): goals, localization, path and distance
left, the outcome and its notice, getPath asked for only while navigating, goalsUpdated; and the
operator always wins — a drive key or STOP cancels with a stop and nothing else, focus loss does not.
Against scripted servers: the order of what goes out, and a server without navigation.
"""

from __future__ import annotations

import shutil
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from rtmu.base.notices import Kind
from rtmu.client.errors import NotSupported
from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.control.controller import Controller
from rtmu.mapfile import MapObject, write_map
from rtmu.model.observables import NavOutcome, OperatorState, Phase, RobotModel
from rtmu.protocol.payloads.drive import RatioDrive
from rtmu.protocol.payloads.robot import ModeInfo
from rtmu.sim import SimThread
from rtmu.sim.project_maps import office_map
from rtmu.values.intents import GotoGoal, GotoPose, Localize
from rtmu.values.target import Target

from .fakes import FakeView
from .navsim import OFFICE, fast_sim, reset, robot
from .servers import SPECS, ServerThread, TestServer
from .uiqueue import UiQueue, eventually


class Rig:
    """A connected runner + model + controller, as the window holds them (the test is the UI thread)."""

    def __init__(self, port: int, **config: object) -> None:
        self.model, self.ui, self.view = RobotModel(), UiQueue(), FakeView()
        self.runner = ClientRunner(self.model, post=self.ui.post, config=SessionConfig(**config))  # type: ignore[arg-type]
        self.runner.start()
        self.ctl = Controller(self.model, OperatorState(), self.runner, self.view)
        self.runner.connect(Target("127.0.0.1", port, profile="test")).result(10)
        self.wait(lambda: self.model.connection.value.phase is Phase.CONNECTED)

    def wait(self, predicate, timeout: float = 10.0) -> None:  # type: ignore[no-untyped-def]
        self.ui.wait_for(predicate, timeout)

    @property
    def nav(self):  # type: ignore[no-untyped-def]
        return self.model.navigation.value

    def hold(self, seconds: float) -> None:
        """Keep the keys held: the UI timer renews the lease every 100 ms."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.ctl.tick()
            self.ui.drain()
            time.sleep(0.05)

    def close(self) -> None:
        self.ctl.close()
        self.runner.close()


@pytest.fixture(scope="module")
def sim() -> Iterator[SimThread]:
    with fast_sim() as s:
        yield s


@pytest.fixture
def rig(sim: SimThread) -> Iterator[Rig]:
    reset(sim)
    eventually(lambda: robot(sim).status == "Stopped", timeout=5)
    r = Rig(sim.port)
    try:
        yield r
    finally:
        r.close()


def server_subscriptions(sim: SimThread) -> set[str]:
    assert sim.server is not None
    server = sim.server
    return sim.call(lambda: {sub.name for s in server.sessions for sub in s.subscriptions.values()})


def test_goals_localization_and_what_the_server_offers(rig: Rig) -> None:
    rig.wait(lambda: "Room 101" in rig.nav.goals and rig.nav.loc_state == "Good")
    assert {"gotoGoal", "gotoPose", "home", "dock", "tourGoals", "getPath"} <= rig.nav.offered
    assert rig.nav.loc_score is not None and rig.nav.loc_score >= 0.9
    assert not rig.nav.navigating and rig.nav.outcome is NavOutcome.NONE


def test_goto_goal_publishes_path_distance_and_arrival(rig: Rig, sim: SimThread) -> None:
    rig.wait(lambda: rig.model.map.value.data is not None and "Room 101" in rig.nav.goals)
    assert "getPath" not in server_subscriptions(sim)
    rig.ctl.ask(GotoGoal("Room 101"))
    rig.wait(lambda: rig.nav.navigating and rig.nav.target == "Room 101")
    assert rig.nav.target_pose == (2000.0, 3200.0, None)
    rig.wait(lambda: len(rig.nav.path) > 0 and (rig.nav.remaining_mm or 0) > 500)
    assert rig.nav.path[-1] == (2000, 3200)
    assert "getPath" in server_subscriptions(sim)  # asked for while navigating…
    first = rig.nav.remaining_mm
    rig.wait(lambda: (rig.nav.remaining_mm or first) < first - 300)  # …and the distance left shrinks
    rig.wait(lambda: rig.nav.outcome is NavOutcome.ARRIVED, timeout=30)
    assert not rig.nav.navigating and rig.nav.path == () and rig.nav.remaining_mm is None
    assert rig.nav.outcome_text == "Arrived at Room 101"
    assert (Kind.NAVIGATION, "Arrived at Room 101") in zip(rig.view.kinds, rig.view.texts(), strict=True)
    eventually(lambda: "getPath" not in server_subscriptions(sim))  # …and no longer after


def test_a_drive_key_cancels_navigation_with_a_stop_and_the_next_press_drives(
    rig: Rig, sim: SimThread
) -> None:
    assert sim.server is not None
    server = sim.server
    rig.ctl.ask(GotoGoal("Corridor End"))
    rig.wait(lambda: rig.nav.navigating)
    eventually(lambda: robot(sim).vel > 100, timeout=10)
    drives = sim.call(lambda: server.robot.ratio_drives_received)
    rig.ctl.press("forward")
    eventually(lambda: robot(sim).mode_name == "stop", timeout=5)
    rig.wait(lambda: rig.nav.outcome is NavOutcome.CANCELLED)
    rig.hold(0.5)  # still held: the key stays blocked, nothing is driven
    # The stop is what STOP always sends: zero ratios, then stop — no motion at all.
    assert sim.call(lambda: server.robot.ratio_drives_received) <= drives + 1
    assert sim.call(lambda: server.robot.received_ratios) in (None, (0.0, 0.0, 0.0, 0.0))
    assert robot(sim).mode_name == "stop"
    assert "Navigation cancelled. Press again to drive." in rig.view.texts()
    rig.ctl.release("forward")
    rig.ctl.press("forward")
    rig.hold(0.5)
    assert robot(sim).mode_name == "ratioDrive"
    assert sim.call(lambda: server.robot.ratio_drives_received) > drives
    rig.ctl.release("forward")
    eventually(lambda: robot(sim).mode_name == "stop", timeout=5)


def test_stop_cancels_navigation_but_focus_loss_does_not(rig: Rig, sim: SimThread) -> None:
    rig.ctl.ask(GotoPose(12000, 6000))
    rig.wait(lambda: rig.nav.navigating and rig.nav.target == "point")
    assert rig.nav.target_pose == (12000.0, 6000.0, None)
    rig.ctl.focus_lost()
    time.sleep(0.5)
    rig.ui.drain()
    assert robot(sim).mode_name == "Goto" and rig.nav.navigating  # autonomy goes on
    rig.ctl.focus_gained()
    rig.ctl.run("stop")
    eventually(lambda: robot(sim).mode_name == "stop", timeout=5)
    rig.wait(lambda: not rig.nav.navigating and rig.nav.outcome is NavOutcome.CANCELLED)


def test_a_lost_robot_fails_with_a_notice_until_localized(rig: Rig, sim: SimThread) -> None:
    assert sim.server is not None
    rig.wait(lambda: rig.nav.loc_state == "Good")
    sim.call(sim.server.lose_localization)
    rig.wait(lambda: rig.nav.loc_state == "Lost")
    rig.ctl.ask(GotoGoal("Room 101"))
    rig.wait(lambda: rig.nav.outcome is NavOutcome.FAILED)
    assert rig.nav.reason == "the robot is lost"
    assert "Failed to get to Room 101 because the robot is lost" in rig.view.texts()
    assert "The robot is lost: localize it before sending it anywhere" in rig.view.texts()
    rig.ctl.ask(Localize(2500, 6000, 0))
    rig.wait(lambda: rig.nav.loc_state == "Good")
    snap = robot(sim)
    assert (round(snap.x), round(snap.y)) == (2500, 6000)


def test_dock_and_home_are_registry_commands_that_reach_the_server(rig: Rig, sim: SimThread) -> None:
    rig.wait(lambda: rig.ctl.command_states()["dock"].enabled)
    assert rig.ctl.command_states()["home"].enabled and rig.ctl.command_states()["tour_goals"].enabled
    assert rig.ctl.run("dock")
    rig.wait(lambda: rig.nav.outcome is NavOutcome.DOCKED, timeout=30)
    assert "Docked" in rig.view.texts()
    assert rig.ctl.run("tour_goals")
    rig.wait(lambda: rig.nav.navigating and rig.nav.target in rig.nav.goals, timeout=15)
    rig.ctl.stop()
    eventually(lambda: robot(sim).mode_name == "stop", timeout=5)


def test_goals_are_asked_again_on_goals_updated(tmp_path: Path) -> None:
    path = tmp_path / "office.map"
    shutil.copy(OFFICE, path)
    with fast_sim(path) as sim:
        rig = Rig(sim.port)
        try:
            rig.wait(lambda: "Room 101" in rig.nav.goals)
            data = office_map()
            data.objects.append(MapObject("Goal", 5000, 6000, 0.0, name="Printer"))
            write_map(data, path)
            rig.runner.call(lambda: rig.runner.session.client.send("checkMap"))  # type: ignore[union-attr]
            rig.wait(lambda: "Printer" in rig.nav.goals)
        finally:
            rig.close()


NAV_SPECS = [
    *SPECS,
    ("gotoGoal", "goal", "string", "none", "Navigation", "RETURN_NONE"),
    ("gotoPose", "point", "byte4 byte4 byte4", "none", "Navigation", "RETURN_NONE"),
]


def test_a_held_drive_is_stopped_before_the_goal_goes_out() -> None:
    with ServerThread(TestServer(NAV_SPECS)) as server:
        rig = Rig(server.port, fetch_map=False)
        try:
            rig.ctl.press("forward")
            eventually(lambda: "ratioDrive" in server.names())
            # Straight to the runner, the lease still live: the session itself must stop first.
            rig.runner.send(GotoGoal("Lab A")).result(5)
            eventually(lambda: "gotoGoal" in server.names())
            rig.hold(0.3)
            names = server.names()
            goal = names.index("gotoGoal")
            assert names[goal - 1] == "stop"  # zero ratios + stop, then the goal
            assert "ratioDrive" not in names[goal:]  # and no drive after it
        finally:
            rig.close()


def test_a_drive_key_while_the_server_navigates_sends_only_stop() -> None:
    with ServerThread(TestServer(NAV_SPECS)) as server:
        server.strings = ("Going to Lab A", "Goto goal", "Going to Lab A")
        server.handlers["getModeInfo"] = lambda side, args: [ModeInfo("Goto").encode()]
        rig = Rig(server.port, fetch_map=False)
        try:
            rig.wait(lambda: rig.nav.navigating and rig.nav.target == "Lab A")
            before = len(server.names())
            rig.ctl.press("left")
            rig.hold(0.3)
            sent = [r for r in server.received[before:] if r.name in ("ratioDrive", "stop")]
            assert [r.name for r in sent] == ["ratioDrive", "stop"]  # what STOP sends, and nothing else
            zero = RatioDrive.decode(sent[0].args)
            assert (zero.trans, zero.rot) == (0.0, 0.0)
        finally:
            rig.close()


def test_a_server_without_navigation_asks_for_none_of_it_and_says_so() -> None:
    with ServerThread(TestServer()) as server:
        rig = Rig(server.port, fetch_map=False)
        try:
            assert rig.nav.offered == frozenset()
            with pytest.raises(NotSupported, match="does not offer gotoGoal"):
                rig.runner.send(GotoGoal("Lab A")).result(5)
            rig.wait(lambda: any(k is Kind.NAVIGATION for k in rig.view.kinds))
            for name in ("dock", "home", "tour_goals"):
                assert not rig.ctl.command_states()[name].enabled
            time.sleep(0.3)
            asked = set(server.names())
            assert not asked & {"getLocState", "getPath", "getGoals", "goalsUpdated", "gotoGoal"}
        finally:
            rig.close()

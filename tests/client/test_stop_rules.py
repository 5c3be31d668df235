"""Issue 21's rules in the controller, one by one (no GTK, no sockets): looking never stops a mission, no
drive starts while Space cannot reach the window, every stop says what to do, the near-people cap
lowers the throttle, and every jog ends with its outcome."""

from __future__ import annotations

import concurrent.futures
from dataclasses import replace

from rtmu.base.notices import Kind
from rtmu.client.config_feed import ConfigSection, ServerConfig
from rtmu.client.lease import DriveRatios
from rtmu.control.controller import Controller
from rtmu.control.motion_limits import ASSUMED_MAX_MM_S
from rtmu.model.observables import (
    ConnectionState,
    LinkHealth,
    LinkLevel,
    NavState,
    NearPeople,
    OperatorState,
    Phase,
    RobotModel,
)
from rtmu.protocol.payloads.config import ConfigParam, ParamType
from rtmu.values.intents import FetchConfig, GotoGoal, Intent, MoveDistance, Stop

from .fakeclock import FakeClock
from .fakes import FakeView, RecordingLink

OFFERS = frozenset({"ratioDrive", "stop", "moveDist", "turnByAngle", "gotoGoal", "getConfigBySectionsV4"})


class Link(RecordingLink):
    """The recording link, answering intents as the runner would (a Future; the config from ``config``)."""

    def __init__(self, clock: FakeClock) -> None:
        super().__init__(clock)
        self.config: ServerConfig | None = None
        self.intents: list[Intent] = []

    def send(self, intent: Intent) -> concurrent.futures.Future[object]:
        self.intents.append(intent)
        self.calls.append(("stop",) if isinstance(intent, Stop) else (type(intent).__name__,))
        future: concurrent.futures.Future[object] = concurrent.futures.Future()
        future.set_result(self.config if isinstance(intent, FetchConfig) else None)
        return future


class View(FakeView):
    def __init__(self) -> None:
        super().__init__()
        self.dialogs: list[str] = []

    def open_dialog(self, name: str) -> None:
        self.dialogs.append(name)


class Rig:
    def __init__(self, config: ServerConfig | None = None) -> None:
        self.clock = FakeClock()
        self.model = RobotModel()
        self.operator = OperatorState()
        self.view = View()
        self.link = Link(self.clock)
        self.link.config = config
        self.ctl = Controller(self.model, self.operator, self.link, self.view, clock=self.clock)
        self.model.connection.set(ConnectionState(Phase.CONNECTED, "127.0.0.1", 7272, offers=OFFERS))
        self.model.health.set(LinkHealth(LinkLevel.OK))
        self.link.finish_blocking()  # the robot's limits, read off the UI thread

    def navigating(self) -> None:
        self.model.navigation.set(NavState(navigating=True, target="Lab B", goals=("Lab B",)))

    def stops(self) -> int:
        return self.link.names().count("stop")

    def moved(self, **changes: object) -> None:
        """100 ms on: the robot's new state (if any), and the window's timer tick."""
        self.clock.advance(0.1)
        self.model.robot.set(replace(self.model.robot.value, **changes))  # type: ignore[arg-type]
        self.ctl.tick()


def test_looking_ends_a_held_drive_but_never_a_navigation() -> None:
    rig = Rig()
    rig.navigating()
    rig.ctl.look("the camera page")
    rig.ctl.open_dialog("commands")
    rig.ctl.look("the menu", keys_leave=True)
    assert rig.stops() == 0 and rig.ctl.navigating, "looking sent a stop"
    assert rig.view.dialogs == ["commands"]
    rig.model.navigation.set(NavState())
    rig.ctl.press("forward")
    assert rig.link.lease.view().live
    rig.ctl.look("the camera page")
    assert not rig.link.lease.view().live, "a held drive ends: its keys go elsewhere"
    assert "Stopped for the camera page. Press again to drive." in rig.view.texts()
    rig.ctl.press("forward")  # the key still held auto-repeats: blocked until released
    assert not rig.link.lease.view().live
    rig.ctl.release("forward")
    rig.ctl.press("forward")
    assert rig.link.lease.view().live


def test_a_menu_taking_the_keys_keeps_a_held_key_blocked_even_when_its_release_is_not_seen() -> None:
    rig = Rig()
    rig.ctl.press("forward")
    rig.ctl.look("the menu", keys_leave=True)
    rig.ctl.release("forward")  # the window forgets its held keys: not a real key-up
    rig.ctl.press("forward")  # the menu closed; the key, held all along, auto-repeats
    assert not rig.link.lease.view().live
    rig.ctl.release("forward")
    rig.ctl.press("forward")
    assert rig.link.lease.view().live


def test_a_pointer_drive_waits_for_the_keys_and_every_focus_stop_says_what_to_do() -> None:
    rig = Rig()
    rig.ctl.press("left")
    rig.ctl.focus_lost()
    assert any(
        t.startswith("Stopped: the window lost the keyboard") and "Click the map" in t
        for t in rig.view.texts()
    )
    assert not rig.ctl.pointer_may_drive()
    assert "Not driving: Space could not stop it" in rig.view.texts()[-1]
    rig.ctl.focus_gained()
    assert rig.ctl.pointer_may_drive()


def test_the_near_people_cap_lowers_the_throttle_of_a_drive_in_progress() -> None:
    rig = Rig()
    rig.operator.speed.set(replace(rig.operator.speed.value, percent=80))
    rig.ctl.press("forward")
    assert rig.link.lease.view().ratios == DriveRatios(100, 0, 80)
    rig.operator.near_people.set(NearPeople(True, 250))
    assert rig.link.lease.view().ratios.throttle == 100 * 250 / ASSUMED_MAX_MM_S, "at once, the same lease"
    rig.operator.near_people.set(NearPeople(False, 250))
    assert rig.link.lease.view().ratios.throttle == 80


def test_the_cap_uses_the_servers_own_top_speed_and_a_faster_robot_seen_lowers_it_further() -> None:
    params = (ConfigParam("TransVelMax", ParamType.INT, 1000),)
    rig = Rig(ServerConfig((ConfigSection("Robot config", "", params),), 0, "V4", 0))
    assert rig.ctl.limits.max_speed == 1000.0
    rig.operator.near_people.set(NearPeople(True, 250))
    rig.ctl.press("forward")
    assert rig.link.lease.view().ratios.throttle == 25.0
    rig.moved(vel=400.0)  # 400 mm/s at 25 %: this robot's full speed is 1600, not 1000
    assert rig.ctl.limits.max_speed == 1600.0
    assert rig.link.lease.view().ratios.throttle == 100 * 250 / 1600


def test_a_jog_ends_with_its_outcome_and_a_stop_or_a_goal_says_what_was_done() -> None:
    rig = Rig()
    rig.ctl.ask(MoveDistance(2000.0))
    rig.moved(x=300.0, vel=350.0)
    rig.moved(x=580.0, vel=0.0, sonar=((1100, 0),))
    for _ in range(6):
        rig.moved()
    said = [t for k, t in zip(rig.view.kinds, rig.view.texts(), strict=True) if k is Kind.NAVIGATION]
    assert said == ["Stopped by an obstacle 0.5 m ahead after 0.58 m of 2.00 m"]
    rig.ctl.ask(MoveDistance(1000.0))
    rig.moved(x=880.0, vel=300.0)
    rig.ctl.stop()
    assert rig.view.texts()[-1] == "Go a distance ended by STOP after 0.30 m of 1.00 m"
    rig.ctl.ask(MoveDistance(1000.0))
    rig.ctl.ask(GotoGoal("Lab B"))
    assert rig.view.texts()[-1] == "Go a distance ended by Go to goal after 0.00 m of 1.00 m"

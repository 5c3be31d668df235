"""The controller's rules, one by one, on a fake clock with a recording view (no GTK, no sockets)."""

from __future__ import annotations

import dataclasses
import threading

import pytest

from rtmu.base.notices import Kind, Level, Notice
from rtmu.client.lease import DriveRatios, EndReason
from rtmu.control.commands import Command, CommandRegistry, CommandTarget
from rtmu.control.controller import Controller
from rtmu.control.held_drive import ratios_for
from rtmu.model.observables import (
    ConnectionState,
    LinkHealth,
    LinkLevel,
    OperatorState,
    Phase,
    RobotModel,
    SpeedSetting,
)
from rtmu.settings.store import Profile
from rtmu.values.intents import (
    GotoGoal,
    Localize,
    MoveDistance,
    RequestPicture,
    RunServerCommand,
    SetSafeDrive,
    TurnBy,
)
from rtmu.values.target import Target

from .fakeclock import FakeClock
from .fakes import FakeView, RecordingLink

ALL = frozenset({"ratioDrive", "stop", "turnByAngle", "moveDist", "setSafeDrive", "getPictureCam1"})


class Rig:
    def __init__(self, offers: frozenset[str] = ALL, connected: bool = True) -> None:
        self.clock = FakeClock()
        self.model = RobotModel()
        self.operator = OperatorState()
        self.view = FakeView()
        self.link = RecordingLink(self.clock)
        self.ctl = Controller(self.model, self.operator, self.link, self.view, clock=self.clock)
        if connected:
            self.connect(offers)

    def connect(self, offers: frozenset[str] = ALL) -> None:
        self.model.connection.set(ConnectionState(Phase.CONNECTED, "127.0.0.1", 7272, offers=offers))
        self.model.health.set(LinkHealth(LinkLevel.OK))

    def hold(self, seconds: float) -> None:
        """Keep the keys held: the UI timer ticks every 100 ms."""
        for _ in range(round(seconds / 0.1)):
            self.clock.advance(0.1)
            self.ctl.tick()

    @property
    def lease(self):  # type: ignore[no-untyped-def]
        return self.link.lease.view()


def test_ratios_combine_into_curves_and_cancel() -> None:
    assert ratios_for({"forward"}, 50) == DriveRatios(100, 0, 50)
    assert ratios_for({"backward"}, 50) == DriveRatios(-100, 0, 50)
    assert ratios_for({"left"}, 30) == DriveRatios(0, 100, 30)
    assert ratios_for({"forward", "right"}, 50) == DriveRatios(100, -50, 50)
    assert ratios_for({"backward", "left"}, 50) == DriveRatios(-100, 50, 50)
    assert not ratios_for({"forward", "backward"}, 50).moving
    assert not ratios_for(set(), 50).moving


def test_hold_drives_and_release_stops() -> None:
    rig = Rig()
    rig.ctl.press("forward")
    assert rig.lease.live and rig.lease.ratios == DriveRatios(100, 0, 50)
    rig.hold(2.0)
    assert rig.lease.live
    rig.ctl.release("forward")
    assert not rig.lease.live and rig.lease.ended is EndReason.RELEASED


def test_auto_repeat_presses_do_not_regrant() -> None:
    rig = Rig()
    rig.ctl.press("forward")
    generation = rig.lease.generation
    rig.ctl.press("forward")
    rig.ctl.press("forward")
    assert rig.lease.generation == generation


def test_two_keys_curve_and_releasing_one_keeps_driving() -> None:
    rig = Rig()
    rig.ctl.press("forward")
    rig.ctl.press("left")
    assert rig.lease.ratios == DriveRatios(100, 50, 50)
    generation = rig.lease.generation
    rig.ctl.release("forward")
    assert rig.lease.live and rig.lease.ratios == DriveRatios(0, 100, 50)
    assert rig.lease.generation == generation
    rig.ctl.press("right")  # left + right cancel: stop
    assert not rig.lease.live


def test_a_frozen_ui_lapses_the_lease_and_held_keys_need_a_fresh_press() -> None:
    rig = Rig()
    rig.ctl.press("forward")
    rig.clock.advance(0.5)  # no tick for 500 ms: the UI was frozen
    rig.ctl.tick()
    assert not rig.lease.live and rig.ctl.held == frozenset()
    assert any("did not respond" in t for t in rig.view.texts())
    rig.ctl.press("forward")  # auto-repeat of the key still down
    assert not rig.lease.live
    rig.ctl.release("forward")
    rig.ctl.press("forward")
    assert rig.lease.live


def test_stop_always_wins_and_is_sent_even_when_stale() -> None:
    rig = Rig()
    rig.ctl.press("forward")
    rig.model.health.set(LinkHealth(LinkLevel.STALE))
    rig.link.calls.clear()
    rig.ctl.stop()
    assert rig.link.names() == ["stop"]
    assert not rig.lease.live
    rig.ctl.press("forward")  # still held through the stop
    assert not rig.lease.live


def test_focus_loss_stops() -> None:
    rig = Rig()
    rig.ctl.press("left")
    rig.ctl.focus_lost()
    assert "stop" in rig.link.names() and not rig.lease.live
    rig.ctl.press("right")  # another key, pressed after focus came back, drives at once
    assert rig.lease.live


def test_a_key_held_through_focus_loss_stays_blocked_until_its_release_is_seen() -> None:
    rig = Rig()
    rig.ctl.press("forward")
    rig.ctl.focus_lost()
    rig.ctl.release("forward")  # the window forgets its held keys on focus loss: not a real key-up
    assert not rig.lease.live
    rig.ctl.press("forward")  # focus is back; the key, held all along, auto-repeats
    rig.hold(0.5)
    rig.ctl.press("forward")
    assert not rig.lease.live and rig.ctl.held == frozenset()
    rig.ctl.release("forward")  # the real key-up
    rig.ctl.press("forward")  # a fresh press drives
    assert rig.lease.live


def test_focus_gained_makes_releases_real_again() -> None:
    rig = Rig()
    rig.ctl.press("forward")
    rig.ctl.focus_lost()
    rig.ctl.focus_gained()
    rig.ctl.release("forward")
    rig.ctl.press("forward")
    assert rig.lease.live


def test_a_stale_link_stops_and_tells_the_operator() -> None:
    rig = Rig()
    rig.ctl.press("forward")
    rig.model.health.set(LinkHealth(LinkLevel.STALE))
    assert not rig.lease.live and rig.lease.ended is EndReason.LINK
    assert "stop" in rig.link.names()
    assert any("stale" in t for t in rig.view.texts())


def test_a_stale_link_noticed_first_by_the_drive_loop_is_still_told_once() -> None:
    """The network thread's drive loop ends the lease for the link before the model's health
    reaches the UI thread; the next tick finds it ended. A fresh-PATH CI run once showed the
    link cell but no banner this way."""
    rig = Rig()
    rig.ctl.press("forward")
    rig.link.lease.end(EndReason.LINK)  # what the drive loop does when it sees the link go stale
    rig.hold(0.1)
    assert rig.view.texts().count("Stopped: the link is stale. Press again once it is back.") == 1
    rig.model.health.set(LinkHealth(LinkLevel.STALE))  # the health arrives afterwards
    assert rig.view.texts().count("Stopped: the link is stale. Press again once it is back.") == 1
    rig.ctl.press("forward")  # still held: blocked until released
    assert not rig.lease.live


def stops(rig: Rig) -> list[str]:
    return [t for t in rig.view.texts() if t.startswith("Stopped")]


def test_a_stop_for_the_link_says_the_network_sides_measured_cause_once() -> None:
    rig = Rig()
    rig.ctl.press("forward")
    cause = (
        "no status from robot:7272 for 0.46 s (learned jitter 90 ms, limit 0.45 s): nothing at all arrived"
    )
    rig.link.lease.end(EndReason.LINK, why=cause)  # the drive loop saw it first and measured it
    rig.hold(0.1)
    rig.model.health.set(LinkHealth(LinkLevel.STALE, cause="(the health's own words, later)"))
    assert stops(rig) == [f"Stopped: the link is stale — {cause}"]
    assert rig.view.kinds[-1] is Kind.LINK


def test_a_stale_health_seen_first_by_the_window_says_the_healths_cause() -> None:
    rig = Rig()
    rig.ctl.press("forward")
    rig.model.health.set(LinkHealth(LinkLevel.STALE, cause="no status for 0.31 s"))
    assert stops(rig) == ["Stopped: the link is stale — no status for 0.31 s"]


def test_a_lapse_says_how_long_the_window_was_silent() -> None:
    rig = Rig()
    rig.ctl.press("forward")
    rig.link.lease.end(EndReason.LAPSED, why="the drive was not renewed for 0.41 s")
    rig.hold(0.1)
    said = "Stopped: the window did not respond in time (the drive was not renewed for 0.41 s)."
    assert stops(rig) == [f"{said} Press again to drive."]
    assert rig.view.kinds[-1] is Kind.SAFETY


def test_focus_loss_while_driving_is_said_with_its_reason_and_only_then() -> None:
    rig = Rig()
    rig.ctl.focus_lost()  # nothing driving: nothing to say
    assert stops(rig) == []
    rig.ctl.focus_gained()
    rig.ctl.press("forward")
    rig.ctl.focus_lost("RTMU was suspended (Ctrl+Z)")
    assert stops(rig) == ["Stopped: RTMU was suspended (Ctrl+Z). Press again to drive."]


def test_after_a_reconnect_the_robot_stays_still_until_a_fresh_press() -> None:
    rig = Rig()
    rig.ctl.press("forward")
    rig.model.connection.update(phase=Phase.RECONNECTING)
    assert not rig.lease.live
    rig.connect()
    rig.hold(0.5)
    rig.ctl.press("forward")  # key auto-repeat while it is still held
    assert not rig.lease.live  # the key held all along does not restart the robot
    rig.ctl.release("forward")
    rig.ctl.press("forward")
    assert rig.lease.live


def test_press_while_disconnected_does_nothing_until_released() -> None:
    rig = Rig(connected=False)
    rig.ctl.press("forward")
    rig.connect()
    rig.ctl.press("forward")
    assert not rig.lease.live
    rig.ctl.release("forward")
    rig.ctl.press("forward")
    assert rig.lease.live


def test_speed_steps_and_limits_and_applies_to_a_drive_in_progress() -> None:
    rig = Rig()
    rig.operator.speed.set(SpeedSetting(90))
    rig.ctl.press("forward")
    rig.ctl.speed_up()
    assert rig.operator.speed.value.percent == 100 and rig.lease.ratios.throttle == 100
    rig.ctl.speed_up()
    assert rig.operator.speed.value.percent == 100
    assert "maximum" in rig.view.texts()[-1]
    for _ in range(12):
        rig.ctl.speed_down()
    assert rig.operator.speed.value.percent == 10 and rig.lease.ratios.throttle == 10
    assert "minimum" in rig.view.texts()[-1]
    with pytest.raises(ValueError):
        SpeedSetting(55)


def test_bounded_moves_need_server_support() -> None:
    rig = Rig(offers=frozenset({"ratioDrive", "stop"}))
    rig.ctl.ask(TurnBy(90))
    rig.ctl.ask(MoveDistance(1000))
    assert rig.link.calls == []
    assert any("turnByAngle" in t for t in rig.view.texts())
    rig.connect(ALL)
    rig.ctl.press("forward")
    rig.ctl.ask(TurnBy(-90))
    rig.ctl.ask(MoveDistance(500))
    assert rig.link.calls == [("command", "turnByAngle", -90.0), ("command", "moveDist", 500.0)]
    assert not rig.lease.live  # a bounded move replaces held driving


def test_image_and_safe_drive() -> None:
    rig = Rig()
    assert rig.ctl.image_source() == "getPictureCam1"
    rig.ctl.ask(RequestPicture())
    rig.ctl.ask(SetSafeDrive(False))
    assert rig.link.calls == [("request_image",), ("set_safe_drive", False)]
    rig.connect(frozenset({"ratioDrive"}))
    rig.ctl.ask(RequestPicture())
    assert rig.view.notices[-1] == (Level.WARNING, "This server does not offer camera pictures")


def test_command_states_follow_the_server_and_only_changes_are_sent() -> None:
    rig = Rig(connected=False)
    assert rig.view.states["drive_forward"].reason == "not connected"
    assert rig.view.states["speed_up"].enabled
    rig.connect(frozenset({"ratioDrive", "stop"}))
    states = rig.view.states
    assert states["drive_forward"].enabled and states["stop"].enabled
    assert not states["turn_left_90"].enabled
    assert states["turn_left_90"].reason == "this server does not offer turnByAngle"
    assert not states["request_image"].enabled and not states["connect"].enabled
    calls = rig.view.state_calls
    rig.ctl.refresh_commands()
    assert rig.view.state_calls == calls  # nothing changed, nothing sent
    assert rig.ctl.run("turn_left_90") is False
    assert rig.ctl.run("drive_forward") and rig.lease.live
    rig.ctl.release_command("drive_forward")
    assert not rig.lease.live


def test_connect_asks_for_the_password_and_uses_the_keyring_when_remembered() -> None:
    rig = Rig(connected=False)
    rig.ctl.select_profile(Profile("lab", "10.0.0.5", 7272, user="alice", zoom=0.5))
    assert rig.operator.view.value.zoom == 0.5
    rig.ctl.connect()
    assert rig.link.calls == [] and len(rig.view.password_asks) == 1
    rig.view.password_asks[0][1]("secret1")
    assert rig.link.calls == [("connect", "10.0.0.5", 7272, "alice", "secret1", "lab")]
    rig.view.password_asks.clear()
    rig.ctl.connect()  # not connected in the model yet, so it may ask again; cancel this time
    rig.view.password_asks[0][1](None)
    assert rig.view.texts()[-1] == "Connection cancelled"

    class Keyring:
        def __init__(self, answer: str | None) -> None:
            self.answer = answer
            self.threads: list[int] = []

        def get(self, profile: Profile) -> str | None:
            self.threads.append(threading.get_ident())
            return self.answer

    rig2 = Rig(connected=False)
    keyring = Keyring("fromkeyring")
    rig2.ctl.secrets = keyring
    rig2.ctl.select_profile(Profile("lab", "h", 1, user="alice", remember_password=True))
    rig2.ctl.connect()
    rig2.ctl.connect()  # a second click while the lookup runs: still one lookup
    assert keyring.threads == [] and rig2.link.names() == ["run_blocking"]  # not on the UI thread
    rig2.link.finish_blocking()
    assert keyring.threads and threading.get_ident() not in keyring.threads
    assert rig2.link.calls[-1][4] == "fromkeyring" and rig2.view.password_asks == []
    # Nothing remembered: the operator is asked, once the (background) answer is in.
    rig3 = Rig(connected=False)
    rig3.ctl.secrets = Keyring(None)
    rig3.ctl.select_profile(Profile("lab", "h", 1, user="alice", remember_password=True))
    rig3.ctl.connect()
    assert rig3.view.password_asks == []
    rig3.link.finish_blocking()
    assert len(rig3.view.password_asks) == 1


def test_the_profile_reaches_the_link_as_one_target_whose_repr_hides_the_password() -> None:
    rig = Rig(connected=False)
    rig.ctl.select_profile(
        Profile("lab", "10.0.0.5", 7272, user="alice", auto_reconnect=False, protocol="5MTX")
    )
    rig.ctl.connect(password="secret1")
    want = Target("10.0.0.5", 7272, "alice", "secret1", profile="lab", auto_reconnect=False, protocol="5MTX")
    assert rig.link.targets == [want]
    assert "secret1" not in repr(want) and "alice" in repr(want)
    with pytest.raises(dataclasses.FrozenInstanceError):
        want.host = "elsewhere"  # type: ignore[misc]
    rig.ctl.select_profile(Profile("any", "h", 1))  # no protocol string: the server's own is answered
    rig.ctl.connect(password="")
    assert rig.link.targets[-1].protocol is None and rig.link.targets[-1].auto_reconnect


def test_a_keyring_answer_for_a_profile_left_meanwhile_is_dropped() -> None:
    class Keyring:
        def get(self, profile: Profile) -> str | None:
            return "old"

    rig = Rig(connected=False)
    rig.ctl.secrets = Keyring()
    rig.ctl.select_profile(Profile("lab", "h", 1, user="alice", remember_password=True))
    rig.ctl.connect()
    rig.ctl.select_profile(Profile("other", "h2", 1, user="bob"))
    rig.link.finish_blocking()
    assert "connect" not in rig.link.names()


def test_disconnect_stops_first() -> None:
    rig = Rig()
    rig.ctl.press("forward")
    rig.ctl.disconnect()
    assert rig.link.names() == ["stop", "disconnect"]
    assert not rig.lease.live


def test_link_notices_reach_the_view() -> None:
    rig = Rig()
    assert rig.link.on_notice is not None
    rig.link.on_notice(Notice.error(Kind.MAP, "the map could not be loaded"))
    assert rig.view.notices[-1] == (Level.ERROR, "the map could not be loaded")


def test_adding_a_command_is_one_class() -> None:
    registry = CommandRegistry()

    @registry.register
    class Wander(Command):
        name = "wander"
        label = "Wander"
        keys = ("w",)
        needs = ("wander",)

        def activate(self, target: CommandTarget) -> None:
            target.ask(RunServerCommand("wander"))

    rig = Rig()
    ctl = Controller(rig.model, rig.operator, rig.link, rig.view, clock=rig.clock, registry=registry)
    assert ctl.command_states()["wander"].reason == "this server does not offer wander"
    rig.connect(ALL | {"wander"})
    assert ctl.run("wander")
    assert rig.link.calls[-1] == ("send", RunServerCommand("wander"))
    assert registry.keys() == {"w": "wander"}


def test_profile_view_options_round_trip() -> None:
    rig = Rig()
    rig.ctl.select_profile(Profile("lab", zoom=0.3, speed=70, follow_robot=False))
    assert rig.operator.speed.value.percent == 70 and rig.operator.view.value.follow_robot is False
    rig.operator.view.update(zoom=0.4)  # the map view zooms itself and stores its zoom here
    rig.ctl.speed_down()
    saved = rig.ctl.current_profile()
    assert (saved.name, saved.zoom, saved.speed, saved.follow_robot) == ("lab", 0.4, 60, False)


@pytest.mark.parametrize(
    ("phase", "enabled"),
    [
        (Phase.DISCONNECTED, False),
        (Phase.CONNECTING, True),
        (Phase.CONNECTED, True),
        (Phase.RECONNECTING, True),
        (Phase.FAILED, False),
    ],
)
def test_disconnect_is_enabled_whenever_there_is_something_to_cancel(phase: Phase, enabled: bool) -> None:
    rig = Rig(connected=False)
    rig.model.connection.set(ConnectionState(phase, "127.0.0.1", 7272))
    assert rig.ctl.command_states()["disconnect"].enabled is enabled
    assert rig.ctl.run("disconnect") is enabled
    assert ("disconnect" in rig.link.names()) is enabled


def test_in_replay_mode_nothing_is_sent_and_every_way_in_says_replay() -> None:
    rig = Rig()
    rig.ctl.replay = "lab.mcap"
    rig.ctl.refresh_commands()
    states = rig.view.states
    assert not states["drive_forward"].enabled and "Replay" in states["drive_forward"].reason
    assert not states["stop"].enabled and not states["request_image"].enabled
    assert states["speed_up"].enabled  # what sends nothing still works
    rig.ctl.press("forward")
    assert rig.ctl.run("drive_forward") is False
    rig.ctl.stop()
    rig.ctl.ask(TurnBy(90))
    rig.ctl.ask(SetSafeDrive(False))
    rig.ctl.ask(GotoGoal("Lab"))
    rig.ctl.ask(Localize(0, 0, 0))
    assert rig.link.calls == [] and rig.lease.generation == 0
    assert sum("Replay" in t for t in rig.view.texts()) >= 6

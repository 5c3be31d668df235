"""A robot at rest costs the window almost nothing (issue 28): its repeated packets are not decoded
again, and nothing is published to the UI thread for them.

Against the real simulator over loopback, the robot standing still: the status stream keeps coming
(counted at ``Session.decode``), but each repeated payload is decoded once (counted at the payload
codec) and no ``RobotChanged`` reaches the UI; once the robot moves, its new pose still does.
Counting, never timing.
"""

from __future__ import annotations

import collections
from collections.abc import Iterator
from typing import Any

import pytest

from linkfaults import TO_CLIENT, FaultProxy
from rtmu.client import drive_loop as drive_loop_module
from rtmu.client import session as session_module
from rtmu.client.drive_loop import DriveFeed
from rtmu.client.runner import ClientRunner
from rtmu.client.session_config import SessionConfig
from rtmu.model.observables import LinkLevel, Phase, RobotModel
from rtmu.sim import SimThread
from rtmu.values.state import DrawingsChanged, RobotChanged, StateChange
from rtmu.values.target import Target
from simulators import simulator

from .uiqueue import UiQueue

sim = simulator()

STATUS = "updateNumbers"


class Counts:
    """Calls of ``Session.decode`` (packets handed to the feeds) and of the codec (real decodes)."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.asked: collections.Counter[str] = collections.Counter()
        self.decoded: collections.Counter[str] = collections.Counter()
        real_decode = session_module.decode_payload
        real_method = session_module.Session.decode

        def decode_payload(name: str, side: Any, payload: bytes) -> Any:
            self.decoded[name] += 1
            return real_decode(name, side, payload)

        def decode(session: Any, name: str, payload: bytes) -> Any:
            self.asked[name] += 1
            return real_method(session, name, payload)

        monkeypatch.setattr(session_module, "decode_payload", decode_payload)
        monkeypatch.setattr(session_module.Session, "decode", decode)


@pytest.fixture
def rig(
    sim: SimThread, monkeypatch: pytest.MonkeyPatch
) -> Iterator[tuple[ClientRunner, RobotModel, UiQueue, Counts, list[StateChange]]]:
    counts = Counts(monkeypatch)
    model, ui = RobotModel(), UiQueue()
    published: list[StateChange] = []
    runner = ClientRunner(model, post=ui.post)
    runner.on_publish = published.append
    runner.start()
    try:
        runner.connect(Target("127.0.0.1", sim.port, profile="t")).result(10)
        ui.wait_for(lambda: model.connection.value.phase is Phase.CONNECTED, 10)
        yield runner, model, ui, counts, published
    finally:
        runner.close()


def test_a_still_robot_is_decoded_once_and_publishes_nothing(rig, sim: SimThread) -> None:  # type: ignore[no-untyped-def]
    runner, model, ui, counts, published = rig
    ui.wait_for(lambda: counts.asked[STATUS] >= 5, 20)  # connected, settled
    asked, decoded = counts.asked[STATUS], counts.decoded[STATUS]
    session = runner.session
    assert session is not None
    settled = session.clock()
    robots = sum(isinstance(c, RobotChanged) for c in published)
    drawings = sum(isinstance(c, DrawingsChanged) for c in published)
    ui.wait_for(lambda: counts.asked[STATUS] >= asked + 20, 30)  # 20 more status packets arrived
    assert counts.decoded[STATUS] - decoded <= 1, "a repeated status payload was decoded again"
    assert sum(isinstance(c, RobotChanged) for c in published) == robots, "a still robot was published"
    assert sum(isinstance(c, DrawingsChanged) for c in published) == drawings, "unchanged drawings published"
    assert runner.status_age() is not None and runner.status_age() < 5.0  # the stream is alive all along
    # The session's own value still says when the newest status came (built when read).
    numbers_at = runner.submit(lambda: session.robot.numbers_at).result(5)
    assert numbers_at is not None and numbers_at > settled

    x0 = model.robot.value.x
    sim.call(lambda: sim.server.world.move_distance(500.0))
    ui.wait_for(lambda: abs(model.robot.value.x - x0) > 100 or abs(model.robot.value.y) > 100, 30)


class HeartCounts:
    """Runs of the drive loop's heart, and status packets noted by it."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.beats = 0
        self.statuses = 0
        real_beat, real_note = DriveFeed._beat, DriveFeed.note_status

        def beat(loop: DriveFeed, now: float) -> None:
            self.beats += 1
            real_beat(loop, now)

        def note_status(loop: DriveFeed, at: float) -> None:
            self.statuses += 1
            real_note(loop, at)

        monkeypatch.setattr(DriveFeed, "_beat", beat)
        monkeypatch.setattr(DriveFeed, "note_status", note_status)


def test_at_rest_the_heart_wakes_for_its_second_not_for_each_status(
    sim: SimThread, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each status moves the link's next deadline; at rest the heart no longer wakes at each deadline
    a status then moves (3 a second for nothing): a timer moved on by the status wakes it instead."""
    counts = HeartCounts(monkeypatch)
    model, ui = RobotModel(), UiQueue()
    runner = ClientRunner(model, post=ui.post)
    runner.start()
    try:
        runner.connect(Target("127.0.0.1", sim.port, profile="t")).result(10)
        ui.wait_for(lambda: counts.statuses >= 10, 20)  # connected, settled
        beats, statuses = counts.beats, counts.statuses
        ui.wait_for(lambda: counts.statuses >= statuses + 60, 60)  # ~6 s of status at 10 Hz
        woken = counts.beats - beats
        assert woken <= 12, f"the heart ran {woken} times for 60 status packets at rest"
    finally:
        runner.close()


def test_at_rest_a_silent_link_is_still_judged_on_time(
    sim: SimThread, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The level timer, not the heart's own sleep, says a silent link is stale: with that sleep and the
    pings' interval (a ping's answer publishes the link's health too) made a minute long, the silence
    is still published as stale."""
    monkeypatch.setattr(drive_loop_module, "HEART_IDLE_SLEEP", 60.0)
    counts = HeartCounts(monkeypatch)
    model, ui = RobotModel(), UiQueue()
    runner = ClientRunner(model, post=ui.post, config=SessionConfig(ping_interval=60.0))
    runner.start()
    with FaultProxy("127.0.0.1", sim.port) as proxy:
        try:
            runner.connect(Target("127.0.0.1", proxy.port, profile="t")).result(10)
            ui.wait_for(lambda: counts.statuses >= 10 and model.health.value.level is LinkLevel.OK, 20)
            proxy.mute(TO_CLIENT)
            ui.wait_for(lambda: model.health.value.level is not LinkLevel.OK, 20)
        finally:
            runner.close()

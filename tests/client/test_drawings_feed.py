"""The window's drawings feed end to end: runner, session and model over loopback.

Against the simulator: both of ARIA's drawings are listed and asked for at their own period, each
sample lands in the model, hiding one ends its request at the simulator and showing it asks again,
and the choice outlives a reconnect. Against a hostile server: markup, an unknown shape, a lying
point count and a 3 998-point flood are each bounded and named, and the good drawings go on.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from rtmu.client.runner import ClientRunner
from rtmu.model.observables import Phase, RobotModel
from rtmu.package_data import project_map
from rtmu.sim import SimThread
from rtmu.values.intents import DrawingChoices, ShowDrawing
from rtmu.values.target import Target
from simulators import simulator

from .drawing_servers import BOLD_POINTS, MARKUP, MAX_POINTS_SENT, SONAR_POINTS, hostile_drawing_server
from .servers import ServerThread
from .uiqueue import UiQueue, eventually

ARENA = project_map("arena.map")
LASER = "sim_lms2xx_1Current"


sim = simulator(scope="module", map_path=ARENA)


class Rig:
    def __init__(self, port: int) -> None:
        self.model, self.ui = RobotModel(), UiQueue()
        self.runner = ClientRunner(self.model, post=self.ui.post)
        self.runner.start()
        self.runner.connect(Target("127.0.0.1", port, profile="test")).result(10)
        self.wait(lambda: self.model.connection.value.phase is Phase.CONNECTED)

    def wait(self, predicate, timeout: float = 10.0) -> None:  # type: ignore[no-untyped-def]
        self.ui.wait_for(predicate, timeout)

    def layer(self, name: str):  # type: ignore[no-untyped-def]
        found = [layer for layer in self.model.drawings.value.layers if layer.name == name]
        return found[0] if found else None

    def close(self) -> None:
        self.runner.close()


@pytest.fixture
def rig(sim: SimThread) -> Iterator[Rig]:
    r = Rig(sim.port)
    try:
        yield r
    finally:
        r.close()


def requested_at(sim: SimThread) -> dict[str, int]:
    """What the simulator is serving each connection now: data name → interval."""
    assert sim.server is not None
    server = sim.server
    return sim.call(
        lambda: {sub.name: sub.interval_ms for s in server.sessions for sub in s.subscriptions.values()}
    )


def test_both_drawings_are_listed_asked_for_at_their_period_and_land_in_the_model(
    rig: Rig, sim: SimThread
) -> None:
    rig.wait(lambda: rig.layer(LASER) is not None and len(rig.layer(LASER).points) > 50)
    rig.wait(lambda: rig.layer("sonarCurrent") is not None and rig.layer("sonarCurrent").points)
    state = rig.model.drawings.value
    assert state.offered and [layer.name for layer in state.layers] == ["sonarCurrent", LASER]  # by layer
    laser = rig.layer(LASER)
    assert (laser.shape, laser.color, laser.size, laser.layer, laser.shown) == (
        "polyDots",
        0x0000FF,
        80,
        75,
        True,
    )
    eventually(lambda: requested_at(sim).get(LASER) == 200 and requested_at(sim).get("sonarCurrent") == 200)
    # The session still hears its sonar through the feed (the recorder and the old overlay use it).
    rig.wait(lambda: len(rig.model.robot.value.sonar) > 0)
    assert set(rig.model.robot.value.sonar) == set(rig.layer("sonarCurrent").points)


def test_hiding_a_drawing_ends_its_request_and_showing_it_asks_again(rig: Rig, sim: SimThread) -> None:
    rig.wait(lambda: rig.layer(LASER) is not None and rig.layer(LASER).points)
    rig.runner.send(ShowDrawing(LASER, False)).result(5)
    rig.wait(lambda: not rig.layer(LASER).shown and rig.layer(LASER).points == ())
    eventually(lambda: LASER not in requested_at(sim))
    assert "sonarCurrent" in requested_at(sim)
    rig.runner.send(ShowDrawing("sonarCurrent", False)).result(5)
    eventually(lambda: "sonarCurrent" not in requested_at(sim))
    # A reconnect keeps the operator's choice: the session's own sonar subscription is ended again.
    rig.runner.disconnect().result(5)
    rig.runner.connect(Target("127.0.0.1", sim.port, profile="test")).result(10)
    rig.wait(lambda: rig.model.connection.value.phase is Phase.CONNECTED and rig.layer(LASER) is not None)
    eventually(lambda: not {LASER, "sonarCurrent"} & set(requested_at(sim)), timeout=5)
    rig.runner.send(ShowDrawing(LASER, True)).result(5)
    rig.wait(lambda: rig.layer(LASER).shown and len(rig.layer(LASER).points) > 50)
    eventually(lambda: requested_at(sim).get(LASER) == 200)


def test_a_hostile_servers_drawings_are_bounded_and_named() -> None:
    with ServerThread(hostile_drawing_server()) as server:
        rig = Rig(server.port)
        try:
            rig.wait(
                lambda: rig.layer("max") is not None and len(rig.layer("max").points) == len(MAX_POINTS_SENT)
            )
            rig.wait(lambda: rig.layer("huge") is not None and rig.layer("huge").problem != "")
            assert (
                rig.layer("huge").points == () and "point count claims 1000000" in rig.layer("huge").problem
            )
            assert rig.layer(MARKUP).points == BOLD_POINTS  # the exact name: no markup, no mnemonic
            rig.wait(lambda: rig.layer("sonarCurrent").points == SONAR_POINTS)
            blob = rig.layer("blob")
            assert not blob.drawable and not blob.shown and not blob.may_toggle
            assert "blob" not in [r.name for r in server.received]  # an unknown shape is never asked for
            assert rig.model.connection.value.phase is Phase.CONNECTED  # nothing of it ended the link
        finally:
            rig.close()


def test_a_remembered_choice_given_before_connecting_keeps_the_drawing_hidden_and_unasked(
    sim: SimThread,
) -> None:
    model, ui = RobotModel(), UiQueue()
    runner = ClientRunner(model, post=ui.post)
    runner.start()
    try:
        runner.send(DrawingChoices({LASER: False})).result(5)
        runner.connect(Target("127.0.0.1", sim.port, profile="test")).result(10)
        ui.wait_for(lambda: any(d.name == LASER for d in model.drawings.value.layers), 10)
        ui.wait_for(
            lambda: any(d.name == "sonarCurrent" and d.points for d in model.drawings.value.layers), 10
        )
        laser = next(d for d in model.drawings.value.layers if d.name == LASER)
        assert not laser.shown and laser.may_toggle and laser.points == ()
        assert LASER not in requested_at(sim)
    finally:
        runner.close()

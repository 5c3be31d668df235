"""The camera head end to end: runner, session, ``client.ptz`` and the model over loopback.

Against the real-time simulator: the camera list, limits and position arrive as ``RobotState.ptz``;
moves reach the simulated head (read back from the simulator's own world); the position is polled
only while watched. Against scripted servers: no camera, a camera without a head, and hostile
lists (huge names, lying counts, out-of-range limits, short position packets) — each bounded, with
a reason, never a crash. ``rtmu ptz`` shows and sets the head.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_CONNECTION, EXIT_OK, EXIT_TIMEOUT, EXIT_UNSUPPORTED, EXIT_USAGE
from rtmu.cli import main
from rtmu.client.ptz import MAX_NAME, NO_HEAD, NO_LIST, POLL_MS
from rtmu.client.runner import ClientRunner
from rtmu.model.observables import Phase, RobotModel
from rtmu.package_data import project_map
from rtmu.protocol.fields import FieldWriter
from rtmu.protocol.payloads.camera import Camera, CameraCommand, CameraData, CameraInfo, CameraList
from rtmu.sim import SimConfig, SimThread
from rtmu.values.intents import PtzMove, WatchPtz
from rtmu.values.target import Target
from simulators import simulator

from .servers import SPECS, ServerThread, TestServer
from .uiqueue import UiQueue

OFFICE = project_map("office.map")


class Rig:
    """A real runner (network thread + session) feeding a model; the test thread is the UI thread."""

    def __init__(self, port: int) -> None:
        self.model, self.ui = RobotModel(), UiQueue()
        self.runner = ClientRunner(self.model, post=self.ui.post)
        self.runner.start()
        self.runner.connect(Target("127.0.0.1", port, "", "", profile="t")).result(10)
        self.wait(lambda: self.model.connection.value.phase is Phase.CONNECTED)

    def wait(self, predicate: Any, timeout: float = 10.0) -> None:
        self.ui.wait_for(predicate, timeout)

    @property
    def ptz(self) -> Any:
        return self.model.robot.value.ptz

    def close(self) -> None:
        self.runner.close()


sim = simulator(scope="module", map_path=OFFICE)


@pytest.fixture
def rig(sim: SimThread) -> Iterator[Rig]:
    sim.call(lambda: _reset(sim))
    r = Rig(sim.port)
    try:
        yield r
    finally:
        r.close()


def _reset(sim: SimThread) -> None:
    assert sim.server is not None
    p = sim.server.world.camera.ptz
    p.pan = p.tilt = p.zoom = 0.0
    p.goal = None


def _head(sim: SimThread) -> tuple[float, float, float]:
    assert sim.server is not None
    p = sim.server.world.camera.ptz
    return sim.call(lambda: (p.pan, p.tilt, p.zoom))


def test_limits_and_position_come_from_the_server(rig: Rig) -> None:
    rig.wait(lambda: rig.ptz is not None and rig.ptz.position is not None)
    ptz = rig.ptz
    assert (ptz.camera, ptz.camera_type, ptz.display_name) == ("Cam1", "VCC4", "Camera")
    assert ptz.movable and ptz.can_rel and ptz.can_abs and ptz.zoom_available
    assert (ptz.pan_range, ptz.tilt_range, ptz.zoom_range) == ((-98, 98), (-30, 88), (0, 100))
    assert ptz.position == (0.0, 0.0, 0.0)


def test_moves_reach_the_simulated_head_and_come_back_as_position(rig: Rig, sim: SimThread) -> None:
    rig.wait(lambda: rig.ptz is not None and rig.ptz.position is not None)
    rig.runner.send(PtzMove(10, -5)).result(5)
    rig.wait(lambda: rig.ptz.position == (10.0, -5.0, 0.0))
    assert _head(sim) == (10.0, -5.0, 0.0)
    rig.runner.send(PtzMove(-40, 20, 50, relative=False)).result(5)
    rig.wait(lambda: rig.ptz.position == (-40.0, 20.0, 50.0))
    # ARIA scales relative turns by (1 - zoom) and rounds away from zero: 10 deg at 50 % → 5 deg.
    rig.runner.send(PtzMove(10, 0, 10)).result(5)
    rig.wait(lambda: rig.ptz.position == (-35.0, 20.0, 60.0))
    # Beyond the limits the server clamps; a missing zoom in setCameraAbs keeps ours (we send it).
    rig.runner.send(PtzMove(200, 0, relative=False)).result(5)
    rig.wait(lambda: rig.ptz.position == (98.0, 0.0, 60.0))


def test_a_turning_head_is_moving_until_its_reading_settles(rig: Rig, sim: SimThread) -> None:
    """The simulated head turns at the VC-C4's speeds: every reading taken before it stopped is
    published as ``moving`` (never as where the head stopped), and the last one is the goal, settled."""
    rig.wait(lambda: rig.ptz is not None and rig.ptz.position is not None)
    seen: list[Any] = []
    rig.model.robot.observe(lambda _old, new: seen.append(new.ptz))
    rig.runner.send(PtzMove(-98, 30, 40, relative=False)).result(5)  # 98° of pan: over a second
    rig.wait(lambda: rig.ptz.moving and rig.ptz.goal == (-98.0, 30.0, 40.0))
    rig.wait(lambda: not rig.ptz.moving, timeout=20)
    assert rig.ptz.position == (-98.0, 30.0, 40.0) and rig.ptz.goal is None
    assert _head(sim) == (-98.0, 30.0, 40.0)
    for state in seen:
        if state is not None and state.position != (-98.0, 30.0, 40.0):
            assert state.moving, f"a reading taken mid-turn was shown as settled: {state.position}"


def test_position_is_polled_only_while_watched(rig: Rig, sim: SimThread) -> None:
    rig.wait(lambda: rig.ptz is not None and rig.ptz.position is not None)
    assert sim.server is not None
    p = sim.server.world.camera.ptz

    def turn(pan: float) -> None:
        sim.call(lambda: setattr(p, "pan", pan))

    turn(30.0)  # someone else moved the head: nobody watches, so nobody hears
    rig.runner.sync()
    rig.ui.drain()
    assert rig.ptz.position == (0.0, 0.0, 0.0)
    rig.runner.send(WatchPtz(True)).result(5)
    rig.wait(lambda: rig.ptz.position == (30.0, 0.0, 0.0))
    turn(-12.5)
    rig.wait(lambda: rig.ptz.position == (-12.5, 0.0, 0.0))
    # A move while polled is read back at once (a request-once right after it), not at the next poll.
    reads = sum(1 for h in sim.server.heard.all() if h.name.startswith("getCameraData") and h.once)
    rig.runner.send(PtzMove(0, 0, 10)).result(5)
    rig.wait(lambda: rig.ptz.position is not None and rig.ptz.position[2] == 10.0)
    rig.wait(
        lambda: (
            sum(1 for h in sim.server.heard.all() if h.name.startswith("getCameraData") and h.once) > reads
        )
    )
    rig.wait(lambda: not rig.ptz.moving)  # a move is read until it settles, watched or not
    rig.runner.send(WatchPtz(False)).result(5)
    rig.runner.sync()
    rig.ui.drain()
    turn(45.0)
    time.sleep(0.6)  # more than two poll periods: a poll still running would have been heard
    rig.ui.drain()
    assert rig.ptz.position == (-12.5, 0.0, 10.0)


def test_a_server_without_cameras_says_so() -> None:
    with SimThread(SimConfig(port=0, map_path=OFFICE, camera=False)) as s:
        r = Rig(s.port)
        try:
            r.wait(lambda: r.ptz is not None)
            assert r.ptz.reason == NO_LIST and not r.ptz.movable
            future = r.runner.send(PtzMove(10, 0))
            with pytest.raises(Exception, match="no cameras"):
                future.result(5)
        finally:
            r.close()


# -- scripted servers: no head, hostile lists ---------------------------------------------------------
CAMERA_SPECS = [
    ("getCameraList", "cameras", "none", "list", "CameraInfo", "RETURN_SINGLE"),
    ("getCameraInfoX", "limits", "none", "limits", "CameraInfo", "RETURN_SINGLE"),
    ("getCameraDataX", "position", "none", "position", "CameraInfo", "RETURN_SINGLE"),
    ("setCameraRelX", "rel", "pan tilt zoom", "none", "CameraControl", "RETURN_NONE"),
]


def _camera(
    name: str = "X", commands: tuple[str, ...] = ("getCameraInfo", "getCameraData", "setCameraRel")
) -> Camera:
    return Camera(name, "PTZ", name, "", tuple(CameraCommand(c, c + "X") for c in commands))


def _server(camera_list: bytes, info: bytes | None = None, data: bytes | None = None) -> TestServer:
    server = TestServer(SPECS + CAMERA_SPECS)
    server.handlers["getCameraList"] = lambda s, a: [camera_list]
    server.handlers["getCameraInfoX"] = lambda s, a: [
        info if info is not None else CameraInfo(-50, 50, -10, 10).encode()
    ]
    server.handlers["getCameraDataX"] = lambda s, a: [
        data if data is not None else CameraData(1, 2, 3).encode()
    ]
    return server


def _connect(server: TestServer, *, until: Callable[[Any], bool] | None = None) -> Any:
    """The head as read after connecting; ``until`` waits for more than the first word (a position
    is a request of its own after the limits: a loaded machine can sync before it comes)."""
    ready = until or (lambda p: bool(p.reason or p.position is not None or p.camera))
    with ServerThread(server) as srv:
        r = Rig(srv.port)
        try:
            r.wait(lambda: r.ptz is not None and ready(r.ptz))
            r.runner.sync()
            r.ui.drain()
            return r.ptz
        finally:
            r.close()


def test_a_camera_without_a_head_greys_the_controls_with_the_reason() -> None:
    ptz = _connect(_server(CameraList((_camera(commands=("getPicture",)),)).encode()))
    assert ptz.reason == NO_HEAD and not ptz.movable


def test_a_scripted_head_is_read_with_its_own_names() -> None:
    ptz = _connect(_server(CameraList((_camera(),)).encode()), until=lambda p: p.position is not None)
    assert (ptz.camera, ptz.pan_range, ptz.tilt_range, ptz.position) == ("X", (-50, 50), (-10, 10), (1, 2, 3))
    assert ptz.can_rel and not ptz.can_abs


def test_huge_names_are_cut_and_a_lying_count_is_a_reason_not_a_crash() -> None:
    # The commands still point at ...X data names the server lists, so the head is usable; its name is cut.
    huge = Camera("H" * 5000, "T" * 5000, "<b>D</b>" * 1000, "", _camera().commands)
    ptz = _connect(_server(CameraList((huge,)).encode()))
    assert len(ptz.camera) == len(ptz.camera_type) == len(ptz.display_name) == MAX_NAME
    assert ptz.display_name.startswith("<b>D</b>")  # kept as text, shown as text
    lying = FieldWriter().byte2(30000).string("Cam").bytes()
    ptz = _connect(_server(lying))
    assert ptz.reason.startswith("the camera list could not be read") and not ptz.movable


def test_hostile_limits_and_positions_are_ignored() -> None:
    # Short packets: no limits, no position — the head still moves relatively.
    ptz = _connect(_server(CameraList((_camera(),)).encode(), info=b"\x01", data=b"\x02\x00"))
    assert ptz.movable and ptz.pan_range == (0.0, 0.0) and ptz.position is None


# -- rtmu ptz --------------------------------------------------------------------------------------------
def test_cli_shows_and_points_the_head(sim: SimThread, capsys: pytest.CaptureFixture[str]) -> None:
    sim.call(lambda: _reset(sim))
    where = f"127.0.0.1:{sim.port}"
    assert main(["ptz", where, "--timeout", cli_timeout(5)]) == EXIT_OK
    out = capsys.readouterr().out
    assert "Cam1 (VCC4): setCameraRel, setCameraAbs, setCameraPct, getCameraData, getCameraInfo" in out
    assert "pan -98…98°, tilt -30…88°, zoom 0…100 %" in out and "position: pan 0°, tilt 0°, zoom 0 %" in out
    assert (
        main(["ptz", where, "--pan", "25", "--zoom", "40", "--json", "--timeout", cli_timeout(5)]) == EXIT_OK
    )
    obj = json.loads(capsys.readouterr().out)
    assert obj["ptz"]["position"] == {"pan": 25.0, "tilt": 0.0, "zoom": 40.0}
    assert _head(sim) == (25.0, 0.0, 40.0)
    assert main(["ptz", where, "--tilt", "-7.5", "--timeout", cli_timeout(5)]) == EXIT_OK  # the others stay
    assert "position: pan 25°, tilt -7.5°, zoom 40 %" in capsys.readouterr().out
    with pytest.raises(SystemExit) as exited:
        main(["ptz", where, "--pan", "nan", "--timeout", cli_timeout(5)])
    assert exited.value.code == EXIT_USAGE and "out of range" in capsys.readouterr().err


def test_cli_without_a_camera_exits_4() -> None:
    with SimThread(SimConfig(port=0, map_path=OFFICE, camera=False)) as s:
        assert main(["ptz", f"127.0.0.1:{s.port}", "--timeout", cli_timeout(5)]) == EXIT_UNSUPPORTED


def test_cli_with_a_camera_list_that_never_comes_is_a_timeout_not_no_head(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The window shows the reason; the command line says what happened: 5 silent, 3 malformed."""
    server = TestServer([*SPECS, *CAMERA_SPECS])  # getCameraList listed, never answered
    with ServerThread(server):
        assert main(["ptz", f"127.0.0.1:{server.port}", "--timeout", "1"]) == EXIT_TIMEOUT
    assert "getCameraList" in capsys.readouterr().err
    server = TestServer([*SPECS, *CAMERA_SPECS])
    server.handlers["getCameraList"] = lambda s, a: [b"\x05\x00"]  # five cameras, then nothing
    with ServerThread(server):
        assert main(["ptz", f"127.0.0.1:{server.port}", "--timeout", cli_timeout(5)]) == EXIT_CONNECTION


def test_a_watched_position_is_polled_again_after_a_reconnect() -> None:
    server = _server(CameraList((_camera(),)).encode())
    thread = ServerThread(server)
    with thread as srv:
        r = Rig(srv.port)
        try:
            r.runner.send(WatchPtz(True)).result(5)
            r.wait(
                lambda: any(
                    x.name == "getCameraDataX" and x.kind == f"request {POLL_MS}" for x in srv.received
                )
            )
            thread.call(lambda: srv.kill(srv.sides[0]))
            r.wait(lambda: len(srv.sides) == 2 and r.model.connection.value.phase is Phase.CONNECTED, 15)
            r.wait(lambda: any(x.side == 1 and x.kind == f"request {POLL_MS}" for x in srv.received), 10)
            r.runner.send(WatchPtz(False)).result(5)
            r.wait(
                lambda: any(
                    x.side == 1 and x.name == "getCameraDataX" and x.kind == "stop" for x in srv.received
                )
            )
        finally:
            r.close()

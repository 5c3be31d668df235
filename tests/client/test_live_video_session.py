"""Live video through the client core (runner → session → LiveVideo) against the simulator on loopback."""

from __future__ import annotations

import time
from typing import Any

from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.model.observables import CameraImage, Phase, RobotModel
from rtmu.package_data import project_map
from rtmu.sim import SimConfig, SimThread
from rtmu.values.intents import StartVideo, StopVideo, VideoShown
from rtmu.values.target import Target
from simulators import simulator

from .uiqueue import UiQueue

ARENA = project_map("arena.map")


TURNING_CAMERA: dict[str, Any] = {"map_path": ARENA, "camera_hz": 20.0, "drive_timeout": 0}
"""Up to 20 new frames/s, and no drive watchdog to stop the robot that ``turn`` sets turning."""


def sim_config(port: int = 0) -> SimConfig:
    return SimConfig(port=port, **TURNING_CAMERA)


def turn(sim: SimThread) -> None:
    assert sim.server is not None
    world = sim.server.world
    sim.call(lambda: world.ratio_drive(0, 40, 100))


sim = simulator(**TURNING_CAMERA)


def start(port: int) -> tuple[ClientRunner, RobotModel, UiQueue, list[CameraImage]]:
    model, ui = RobotModel(), UiQueue()
    runner = ClientRunner(model, post=ui.post, config=SessionConfig(guardian=False))
    runner.start()
    runner.connect(Target("127.0.0.1", port, profile="test")).result(5)
    ui.wait_for(lambda: model.connection.value.phase is Phase.CONNECTED)
    frames: list[CameraImage] = []
    model.camera.observe(lambda _old, new: new is not None and new.video is not None and frames.append(new))
    return runner, model, ui, frames


def play_for(ui: UiQueue, seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        ui.drain()
        time.sleep(0.02)


def test_live_frames_arrive_stamped_and_wait_for_the_window(sim: SimThread) -> None:
    runner, model, ui, frames = start(sim.port)
    try:
        turn(sim)
        runner.send(StartVideo(fps=20)).result(5)
        ui.wait_for(lambda: len(frames) >= 1, timeout=10)
        first = frames[0]
        assert first.stamp_ns is not None and first.video is not None
        assert (first.width, first.height) == (320, 240) and first.jpeg[:2] == b"\xff\xd8"
        # Nobody says a frame was shown: the loop waits (1 s at most) instead of piling frames up.
        play_for(ui, 2.5)
        unshown = len(frames)
        assert unshown <= 6, unshown
        # The window reports every frame it drew: now they flow at the asked rate.
        model.camera.observe(lambda _o, new: new is not None and runner.send(VideoShown(new.frame or 0)))
        runner.send(VideoShown(frames[-1].frame or 0))
        count = len(frames)
        play_for(ui, 2.5)
        assert len(frames) - count > unshown, (len(frames) - count, unshown)
        assert len({f.sequence for f in frames}) == len(frames)
        assert len({f.stamp_ns for f in frames}) == len(frames), "every frame handed on is a new one"
        runner.send(StopVideo()).result(5)
        play_for(ui, 0.5)
        count = len(frames)
        play_for(ui, 1.0)
        assert len(frames) == count, "stopped"
    finally:
        runner.close()


def test_live_video_resumes_by_itself_after_the_link_comes_back() -> None:
    sim = SimThread(sim_config()).start()
    port = sim.port
    runner, model, ui, frames = start(port)
    try:
        model.camera.observe(lambda _o, new: new is not None and runner.send(VideoShown(new.frame or 0)))
        turn(sim)
        runner.send(StartVideo(fps=10)).result(5)
        ui.wait_for(lambda: len(frames) >= 2, timeout=10)
        sim.kill()
        ui.wait_for(lambda: model.connection.value.phase is not Phase.CONNECTED, timeout=10)
        with SimThread(sim_config(port)) as again:
            ui.wait_for(lambda: model.connection.value.phase is Phase.CONNECTED, timeout=20)
            turn(again)
            count = len(frames)
            ui.wait_for(lambda: len(frames) >= count + 3, timeout=10)
    finally:
        runner.close()
        sim.stop()

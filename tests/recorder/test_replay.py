"""Replay: a recording fed back through a fresh session (the live client code) rebuilds what was recorded.

A real session records the simulator (map, pictures, a drive); the file is then read with
RTMU's replay reader and played through a ``ClientRunner`` whose opener is the replayer —
no socket, no simulator. The robot it rebuilds is held against the recording's own
``/robot/pose`` channel (read with the ``mcap`` package), at the end and after seeks.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import pytest

from rtmu.client.errors import MotionRefused
from rtmu.client.roles import Role
from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.protocol.packet import encode_packet
from rtmu.protocol.payloads.drive import RatioDrive
from rtmu.recorder import Recorder, RecorderConfig
from rtmu.recorder.replay import REPLAY_CONFIG, PacedLink, ReplayClock, Replayer
from rtmu.recorder.replay_file import ReplayFileError, compressed_image_data, load
from rtmu.sim import SimConfig, SimThread
from rtmu.values import intents
from rtmu.values.intents import RequestPicture
from rtmu.values.state import CameraChanged, MapChanged, MapPhase, RobotChanged, StateChange
from rtmu.values.target import Target

from .poses import poses, recorded_pose_at
from .simsession import hold, recorded_session


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    directory = tmp_path_factory.mktemp("replay")
    with recorded_session(directory) as (session, ui, _view, sim):
        ui.wait_for(lambda: session.state.map.value.state is MapPhase.READY, timeout=15)
        for _ in range(2):
            before = session.state.camera.value
            session.controller.ask(RequestPicture())
            ui.wait_for(lambda b=before: session.state.camera.value is not b, timeout=5)
        hold(ui, session, "forward", 1.2)
        hold(ui, session, "left", 0.8)
        # Ended with the robot still, and its last pose read: the session's goodbye reads the server's
        # last bytes after the recording's pose channel has closed, and a robot still creeping then
        # (a loaded machine) is 1 mm further in those bytes than in the channel.
        until(lambda: (s := sim.snapshot()).vel == 0 and s.rot_vel == 0)
        ui.wait_for(lambda: not session.state.robot.value.moving, timeout=10)  # a status sent since
        time.sleep(0.4)
        ui.drain()
    (path,) = directory.glob("*.mcap")
    return path


def replaying(path: Path) -> tuple[ClientRunner, Replayer, list[StateChange]]:
    seen: list[StateChange] = []
    recorded = load(path)
    replayer = Replayer(recorded, publish=seen.append)
    runner = ClientRunner(opener=replayer.open, config=REPLAY_CONFIG)
    runner.on_publish = seen.append
    runner.start()
    return runner, replayer, seen


def until(predicate: Callable[[], bool], timeout: float = 30.0) -> None:
    end = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < end, "timed out"
        time.sleep(0.02)


def last_pose(seen: list[StateChange]) -> tuple[float, float]:
    robot = [c.value for c in seen if isinstance(c, RobotChanged)][-1]
    return (round(robot.x), round(robot.y))


def test_a_replay_at_x8_ends_with_the_robot_where_the_recording_left_it(recording: Path) -> None:
    runner, replayer, seen = replaying(recording)
    try:
        replayer.clock.set_speed(8.0)
        replayer.clock.play()
        runner.connect(Target("replay", 0, auto_reconnect=False))
        until(lambda: replayer.link is not None and replayer.link.exhausted)
        runner.sync()
        time.sleep(0.3)
        recorded = poses(recording)
        assert len({p for _, p in recorded}) > 5, "the recording saw the robot move"
        link = replayer.link
        assert isinstance(link, PacedLink) and link.refused == 0
        assert last_pose(seen) == recorded_pose_at(recording, link.delivered_ns)
        assert last_pose(seen) != (0, 0)
        assert any(isinstance(c, MapChanged) and c.value.state is MapPhase.READY for c in seen)
        assert sum(isinstance(c, CameraChanged) for c in seen) >= 1
    finally:
        runner.close()


def test_seeking_back_rebuilds_from_the_start_and_forward_only_moves_the_clock(recording: Path) -> None:
    runner, replayer, seen = replaying(recording)
    clock = replayer.clock
    try:
        recorded = poses(recording)
        middle = recorded[len(recorded) // 2][0]
        clock.seek(clock.end_ns)  # forward: everything is due at once, paused
        runner.connect(Target("replay", 0, auto_reconnect=False))
        until(lambda: replayer.link is not None and replayer.link.exhausted)
        runner.sync()
        end = replayer.link
        assert end is not None
        at_end = last_pose(seen)
        assert at_end == recorded_pose_at(recording, end.delivered_ns)
        assert replayer.seek_needs_rebuild(middle)
        clock.seek(middle)
        seen.clear()
        runner.connect(Target("replay", 0, auto_reconnect=False))  # backward: a new connection from the start
        until(lambda: replayer.opened == 2)
        link = replayer.link
        assert link is not None
        chunks = replayer.recorded.chunks
        due = sum(1 for c in chunks if c.at_ns <= middle)
        until(lambda: link.position >= due)
        time.sleep(0.3)
        runner.sync()
        assert link.position == due, "nothing after the seek point while paused"
        assert replayer.opened == 2
        assert last_pose(seen) == recorded_pose_at(recording, link.delivered_ns)
        assert last_pose(seen) != at_end
    finally:
        runner.close()


def test_a_replay_is_an_observer_and_its_link_refuses_drive_packets(recording: Path) -> None:
    runner, replayer, _seen = replaying(recording)
    try:
        replayer.clock.seek(replayer.clock.end_ns)
        runner.connect(Target("replay", 0, auto_reconnect=False))
        until(lambda: replayer.link is not None and replayer.link.exhausted)
        link = replayer.link
        assert link is not None and runner.session is not None and runner.session.client is not None
        assert runner.session.client.role is Role.OBSERVER
        written = link.written
        runner.stop_and_wait(2.0)  # STOP, a navigation: the observer's client puts neither on the link
        with pytest.raises(MotionRefused):
            runner.send(intents.GotoGoal(name="anywhere")).result(5)
        runner.sync()
        assert link.written == written and link.refused == 0
        # …and the link itself refuses a drive packet that reaches it some other way.
        link.write(encode_packet(next(iter(link.recorded.motion)), RatioDrive(50.0, 0.0, 50.0).encode()))
        assert link.refused == 1
    finally:
        runner.close()


def test_the_clock_plays_pauses_and_keeps_its_speed_within_bounds() -> None:
    now = [100.0]
    clock = ReplayClock(0, 10_000_000_000, clock=lambda: now[0])
    assert clock.now_ns() == 0 and clock.due_in(1) is None
    clock.set_speed(4.0)
    clock.play()
    now[0] += 1.0
    assert clock.now_ns() == 4_000_000_000
    assert clock.due_in(6_000_000_000) == pytest.approx(0.5)
    clock.pause()
    now[0] += 5.0
    assert clock.now_ns() == 4_000_000_000
    clock.seek(99_000_000_000)
    assert clock.now_ns() == 10_000_000_000 and clock.finished
    for bad in (0.1, 16.0):
        with pytest.raises(ValueError, match="between"):
            clock.set_speed(bad)


def test_bad_files_are_refused_with_the_reason(tmp_path: Path, recording: Path) -> None:
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"not an mcap at all" * 100)
    with pytest.raises(ReplayFileError):
        load(junk)
    with pytest.raises(ReplayFileError, match="no connection 7"):
        load(recording, conn=7)
    cut = tmp_path / "cut.mcap"
    data = recording.read_bytes()
    cut.write_bytes(data[: len(data) * 2 // 3])
    partial = load(cut)  # a file cut short by a crash replays up to its last complete chunk
    assert 0 < len(partial.chunks) < len(load(recording).chunks)
    assert compressed_image_data(b"\x12\xff\xff\xff\xff\x0f") is None  # a size that lies
    assert compressed_image_data(b"\x12\x03abc") == b"abc"


def test_a_recording_with_two_connections_replays_the_one_asked_for(tmp_path: Path) -> None:
    out = tmp_path / "two.mcap"
    recorder = Recorder(RecorderConfig(tmp_path, path=out))
    with SimThread(SimConfig(port=0, seed=1)) as sim:
        runner = ClientRunner(config=SessionConfig(fetch_map=False), opener=recorder.opener())
        recorder.attach(runner)
        with runner:
            runner.connect(Target("127.0.0.1", sim.port)).result(10)
            until(lambda: runner.session is not None and runner.session.client is not None
                  and runner.session.client.packets_received >= 5)  # fmt: skip
            sim.call(lambda: sim.server.world.ratio_drive(50.0, 0.0, 50.0))  # type: ignore[union-attr]
            time.sleep(1.0)  # the second connection starts with the robot elsewhere
            runner.connect(Target("127.0.0.1", sim.port)).result(10)
            until(lambda: runner.session is not None and runner.session.client is not None
                  and runner.session.client.packets_received >= 5)  # fmt: skip
            time.sleep(0.3)
        recorder.close()
    first, second = load(out), load(out, 2)
    assert first.connections == second.connections == 2
    assert first.chunks[0].at_ns < first.end_ns <= second.chunks[0].at_ns
    for recorded in (first, second):
        replayer = Replayer(recorded)
        seen: list[StateChange] = []
        runner = ClientRunner(opener=replayer.open, config=REPLAY_CONFIG, clock=replayer.clock.seconds)
        runner.on_publish = seen.append
        with runner:
            replayer.clock.seek(replayer.clock.end_ns)
            runner.connect(Target("replay", 0, auto_reconnect=False))
            until(lambda r=replayer: r.link is not None and r.link.exhausted)
            runner.sync()
        assert any(isinstance(c, RobotChanged) for c in seen)
    with pytest.raises(ReplayFileError, match="2 connection"):
        load(out, 3)


def test_what_a_replay_keeps_in_memory_is_bounded(recording: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from rtmu.recorder import replay_file

    full = load(recording)
    assert len(full.images) >= 2
    monkeypatch.setattr(replay_file, "MAX_IMAGE_BYTES", len(full.images[0][1]) + 1)
    thinned = load(recording)
    assert len(thinned.images) < len(full.images)
    assert any("thinned" in w for w in thinned.warnings)
    monkeypatch.setattr(replay_file, "MAX_REPLAY_BYTES", 10_000)
    with pytest.raises(ReplayFileError, match="too long to replay"):
        load(recording)

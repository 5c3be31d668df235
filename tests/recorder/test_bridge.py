"""The live Foxglove bridge: a real WebSocket client subscribes and drives, against the simulator.

The bridge taps a real session (``ClientRunner``) connected to the simulator over loopback;
the client is :mod:`.foxglove_client` (the ``websockets`` package, speaking the protocol
from its spec). Poses arrive and match the simulated robot; a client that subscribes after
the map loaded still gets it; without ``allow_drive`` nothing a client publishes moves the
robot (and client publishing is not even advertised); with it, a Twist stream at 10 Hz drives
and the robot is stopped soon after the stream ends, a 3 Hz stream never drives, and junk
messages neither drive nor keep a drive alive.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager

from rtmu.client.lease import DriveLease, EndReason
from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.recorder import topics
from rtmu.recorder.bridge import LEASE_TTL, QUEUE_SIZE, Bridge, DriveLimits, TwistDrive, twist_ratios
from rtmu.sim import SimConfig, SimThread
from rtmu.values.state import (
    ConnectionChanged,
    MapChanged,
    MapPhase,
    Phase,
    RobotChanged,
    RobotState,
    StateChange,
)
from rtmu.values.target import Target

from .foxglove_client import FoxgloveClient, twist
from .poses import _position
from .simsession import ARENA


@contextmanager
def bridged(*, drive: bool) -> Iterator[tuple[SimThread, ClientRunner, Bridge, list[float]]]:
    """Simulator + session + bridge on a free port; the list gets the time of every stop the session sent."""
    with SimThread(SimConfig(port=0, map_path=ARENA, seed=3)) as sim:
        runner = ClientRunner(config=SessionConfig(), lease_ttl=LEASE_TTL)
        bridge = Bridge(port=0, lease=runner.lease if drive else None)
        stops: list[float] = []
        ready: list[StateChange] = []

        def published(change: StateChange) -> None:
            bridge.published(change)
            if isinstance(change, (ConnectionChanged, MapChanged)):
                ready.append(change)

        def stopped(reason: str, sent: bool) -> None:
            stops.append(time.monotonic())
            bridge.stopped(reason, sent)

        runner.on_publish = published
        runner.on_stop = stopped
        bridge.start()
        runner.start()
        try:
            runner.connect(Target("127.0.0.1", sim.port, auto_reconnect=False)).result(10)
            end = time.monotonic() + 15
            while not any(isinstance(c, MapChanged) and c.value.state is MapPhase.READY for c in ready):
                assert time.monotonic() < end, "the map never loaded"
                time.sleep(0.05)
            assert any(isinstance(c, ConnectionChanged) and c.value.phase is Phase.CONNECTED for c in ready)
            yield sim, runner, bridge, stops
        finally:
            bridge.close()
            runner.stop_and_wait(1.0)
            runner.close()


def url(bridge: Bridge) -> str:
    return bridge.url


def stream(client: FoxgloveClient, payload: bytes, hz: float, seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        client.publish(1, payload)
        client.pump(1.0 / hz)


def test_a_client_gets_live_poses_and_the_map_it_subscribed_to_after_it_loaded() -> None:
    with bridged(drive=False) as (sim, _runner, bridge, _stops), FoxgloveClient(url(bridge)) as client:
        client.until(lambda: bool(client.server_info))
        assert "clientPublish" not in client.server_info.get("capabilities", [])
        client.subscribe(topics.POSE, topics.MAP, topics.STATUS, topics.LASER)
        client.until(lambda: bool(client.of(topics.MAP)), 5)  # the map was published before we came
        client.until(lambda: bool(client.of(topics.LASER)), 5)  # a Pioneer's laser (sim_lms2xx_1Current)
        assert client.channels[topics.LASER]["schemaName"] == "foxglove.PointCloud"
        assert client.channels[topics.POSE]["schemaName"] == "foxglove.PoseInFrame"
        # Someone else drives the simulated robot: the poses follow it.
        sim.call(lambda: sim.server.world.ratio_drive(60.0, 0.0, 60.0))  # type: ignore[union-attr]
        client.pump(1.5)
        sim.call(lambda: sim.server.world.stop())  # type: ignore[union-attr]
        client.pump(0.8)
        poses = [_position(m.data) for m in client.of(topics.POSE)]
        assert len(set(poses)) > 3, poses
        robot = sim.snapshot()
        assert abs(poses[-1][0] - robot.x) < 60 and abs(poses[-1][1] - robot.y) < 60
        assert client.of(topics.STATUS)
        assert bridge.dropped == 0


def test_without_allow_drive_nothing_a_client_publishes_moves_the_robot() -> None:
    with bridged(drive=False) as (sim, runner, bridge, _stops), FoxgloveClient(url(bridge)) as client:
        client.until(lambda: bool(client.server_info))
        client.advertise(1, "/cmd_vel")
        start = sim.snapshot()
        stream(client, twist(1.0), hz=10, seconds=1.5)
        robot = sim.snapshot()
        assert robot.trans_ratio == 0 and abs(robot.vel) < 1.0
        assert abs(robot.x - start.x) < 5
        assert runner.lease.view().generation == 0, "no lease was ever granted"


def test_with_allow_drive_a_10_hz_twist_stream_drives_and_its_end_stops_the_robot() -> None:
    with bridged(drive=True) as (sim, _runner, bridge, stops), FoxgloveClient(url(bridge)) as client:
        client.until(lambda: bool(client.server_info))
        assert "clientPublish" in client.server_info["capabilities"]
        client.advertise(1, "/cmd_vel")
        client.pump(0.2)
        start = sim.snapshot()
        stream(client, twist(0.6), hz=10, seconds=1.5)
        moving = sim.snapshot()
        assert moving.trans_ratio > 0 and moving.x > start.x + 50, (start, moving)
        last = time.monotonic()
        end = last + 3
        while sim.snapshot().trans_ratio != 0:
            assert time.monotonic() < end, "the robot was never stopped"
            time.sleep(0.01)
        stopped_after = time.monotonic() - last
        # The bridge's lease lives 220 ms; generous for a loaded machine (bench/bench_bridge.py: the figure).
        assert stopped_after < 1.0, stopped_after
        # The session's stop tap runs after both packets are sent, and the simulator may hear the zero
        # ratios first: wait (bounded) for the session to say it sent the stop.
        told = time.monotonic() + 2
        while not (stops and stops[-1] > last):
            assert time.monotonic() < told, "the session never said it stopped the robot"
            time.sleep(0.01)
        assert bridge.drive is not None and bridge.drive.received >= 10


def test_a_slow_stream_and_junk_never_drive() -> None:
    with bridged(drive=True) as (sim, _runner, bridge, _stops), FoxgloveClient(url(bridge)) as client:
        client.until(lambda: bool(client.server_info))
        client.advertise(1, "/cmd_vel")
        stream(client, twist(1.0), hz=3, seconds=1.5)  # below 5 Hz
        assert sim.snapshot().trans_ratio == 0
        for junk in (
            b"{",
            b'{"linear": {"x": "NaN"}}',
            b"[1, 2]",
            b'{"linear": {"x": 1e999}}',
            b"x" * 10_000,
        ):
            stream(client, junk, hz=10, seconds=0.3)
        assert sim.snapshot().trans_ratio == 0
        assert bridge.drive is not None and bridge.drive.rejected >= 10


def test_twist_ratios_are_bounded_and_refuse_what_is_no_twist() -> None:
    limits = DriveLimits(max_linear=0.5, max_angular=1.0, throttle=40.0)
    r = twist_ratios(twist(2.0, -0.25), limits)
    assert r is not None and (r.trans, r.rot, r.throttle) == (100.0, -25.0, 40.0)
    assert twist_ratios(b'{"linear": {"x": Infinity}}', limits) is None
    assert twist_ratios(b"[" * 100_000, limits) is None
    assert twist_ratios(b'{"linear": 3}', limits) is None


class Manual:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_the_drive_rules_two_quick_messages_start_a_gap_ends_a_stop_needs_a_pause() -> None:
    clock = Manual()
    lease = DriveLease(ttl=LEASE_TTL, clock=clock)
    drive = TwistDrive(lease, DriveLimits(), clock=clock)

    def send(dt: float, linear: float = 0.5) -> bool:
        clock.now += dt
        drive.message(twist(linear))
        return lease.view().live

    assert not send(0.0), "one message alone never drives"
    assert send(0.1), "the second within 200 ms does"
    assert send(0.1) and send(0.19)
    assert not send(0.25), "a gap over 200 ms ends the drive"
    assert send(0.1), "a quick pair starts it again"
    assert not send(0.1, 0.0), "a zero Twist stops at once"
    assert send(0.1), "a live stream after a zero Twist is a fresh press"
    lease.end(EndReason.STOPPED)  # STOP, a stale link…: not the stream's doing
    assert not send(0.1) and not send(0.1), "the stream must pause before it drives again"
    assert not send(0.3) and send(0.1)
    generation = lease.view().generation
    for _ in range(500):  # a flood: renewals only, no new grant, no ratio change faster than 50 Hz
        send(0.001, 0.9)
    view = lease.view()
    assert view.live and view.generation == generation
    drive.stop()
    assert not lease.view().live


def test_a_flood_of_updates_is_dropped_and_counted_never_queued_without_bound() -> None:
    bridge = Bridge(port=0).start()
    try:
        for i in range(20_000):  # far faster than any session publishes
            bridge.published(RobotChanged(RobotState(x=float(i), y=0.0, th=0.0, numbers_at=1.0)))
        assert bridge._queue.qsize() <= QUEUE_SIZE and bridge.dropped > 0
        end = time.monotonic() + 20
        while bridge._queue.qsize() and time.monotonic() < end:
            time.sleep(0.05)
        assert bridge.dropped + bridge.published_messages >= 20_000
    finally:
        bridge.close()

"""The client core end to end against the bundled simulator (``rtmu sim``) over real sockets."""

from __future__ import annotations

import threading
import time
from pathlib import Path

import pytest

from rtmu.client.connection import AriaClient
from rtmu.client.errors import LoginRejected
from rtmu.client.lease import DriveRatios
from rtmu.client.reconnect import Backoff
from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.control.controller import Controller
from rtmu.model.observables import LinkLevel, OperatorState, Phase, RobotModel
from rtmu.package_data import project_map
from rtmu.sim import SimConfig, SimThread
from rtmu.values.intents import RequestPicture, SetSafeDrive
from rtmu.values.target import Target

from .fakeclock import FakeClock
from .fakes import FakeView
from .servers import run
from .uiqueue import UiQueue, eventually

ARENA = project_map("arena.map")


def sim_config(**kw: object) -> SimConfig:
    return SimConfig(port=0, map_path=ARENA, seed=1, **kw)  # type: ignore[arg-type]


def connected_runner(port: int, clock=None, *, auto_reconnect: bool = True, **config):  # type: ignore[no-untyped-def]
    model, ui = RobotModel(), UiQueue()
    runner = ClientRunner(model, post=ui.post, clock=clock or time.monotonic, config=SessionConfig(**config))
    runner.start()
    runner.connect(Target("127.0.0.1", port, profile="sim", auto_reconnect=auto_reconnect)).result(10)
    ui.wait_for(lambda: model.connection.value.phase is Phase.CONNECTED)
    return runner, model, ui


def test_model_from_the_simulator_map_image_wifi_safe_drive() -> None:
    with SimThread(sim_config()) as sim:
        runner, model, ui = connected_runner(sim.port)
        try:
            ui.wait_for(lambda: model.map.value.state == "ready", timeout=10)
            snap = sim.snapshot()
            ui.wait_for(lambda: abs(model.robot.value.x - snap.x) < 2 and model.robot.value.status != "")
            robot = model.robot.value
            assert robot.battery_v is not None and robot.battery_low is not None
            assert robot.mode_name != "" or robot.mode != ""
            assert model.map.value.data.num_lines > 0  # type: ignore[attr-defined]
            ui.wait_for(lambda: model.robot.value.wifi_quality is not None, timeout=5)
            ui.wait_for(lambda: len(model.robot.value.sonar) > 0, timeout=5)
            assert model.robot.value.wifi_signal is not None and model.robot.value.wifi_signal < 0
            image = runner.send(RequestPicture()).result(5)
            assert image.jpeg[:2] == b"\xff\xd8" and image.width > 0
            ui.wait_for(lambda: model.camera.value is not None)
            runner.send(SetSafeDrive(False)).result(5)
            ui.wait_for(lambda: model.robot.value.safe_drive is False)
            assert sim.snapshot().safe_drive is False
            ui.wait_for(lambda: model.health.value.rtt_ms is not None)
            assert model.health.value.level is LinkLevel.OK and model.health.value.dropped == 0
        finally:
            runner.close()


def test_controller_hold_release_and_frozen_ui_on_a_manual_clock() -> None:
    """Sim and client clocks advance together; nothing waits for motion in real time."""
    with SimThread(sim_config(realtime=False)) as sim:
        clock = FakeClock()
        runner, model, ui = connected_runner(sim.port, clock=clock, fetch_map=False)
        view = FakeView()
        ctl = Controller(model, OperatorState(), runner, view, clock=clock)
        try:

            def step(seconds: float = 0.1, tick: bool = True) -> None:
                clock.advance(seconds)
                if tick:
                    ctl.tick()
                runner.sync()
                sim.advance(seconds)
                session = runner.session
                assert session is not None
                # Wait until the status the simulator just sent has been read (its age is then 0).
                eventually(lambda: runner.call(lambda: session.drive.health.status_age(clock()) == 0.0))
                ui.drain()

            step()
            x0 = sim.snapshot().x
            ctl.press("forward")
            for _ in range(10):
                step()
            snap = sim.snapshot()
            assert (snap.trans_ratio, snap.throttle_ratio) == (100, 50)
            assert snap.x > x0 + 50  # it moved (heading 0 in the arena's home)
            ctl.release("forward")
            runner.sync()
            sim.advance(0.5)
            snap = sim.snapshot()
            assert snap.trans_ratio == 0 and snap.mode_name == "stop"
            # Drive again, then the UI freezes: no ticks. The network side stops within 300 ms.
            ctl.press("left")
            step()
            assert sim.snapshot().rot_ratio == 100
            for _ in range(4):
                step(tick=False)
            snap = sim.snapshot()
            assert snap.rot_ratio == 0 and snap.mode_name == "stop"
            assert snap.watchdog_stops == 0  # our stop, not the server's 2 s watchdog
        finally:
            runner.close()


def test_reconnect_restores_status_and_map_but_never_motion() -> None:
    with SimThread(sim_config()) as sim:
        port = sim.port
        runner, model, ui = connected_runner(port, backoff=lambda: Backoff(initial=0.05, jitter=0.0))
        try:
            ui.wait_for(lambda: model.map.value.state == "ready", timeout=10)
            generation = model.map.value.generation
            runner.lease.grant(DriveRatios(100, 0, 30))
            renewing = threading.Event()

            def ui_thread_renews() -> None:  # an operator holding the key throughout
                while not renewing.is_set():
                    runner.lease.renew()
                    time.sleep(0.05)

            holder = threading.Thread(target=ui_thread_renews)
            holder.start()
            try:
                eventually(lambda: sim.snapshot().trans_ratio == 100)
                sim.kill()
                ui.wait_for(lambda: model.connection.value.phase is Phase.RECONNECTING)
                with SimThread(SimConfig(port=port, map_path=ARENA, seed=2)) as sim2:
                    ui.wait_for(lambda: model.connection.value.phase is Phase.CONNECTED, timeout=10)
                    # The same map file (same getMapId): answered from the cache, not downloaded.
                    ui.wait_for(lambda: runner.session.maps.downloads_skipped >= 1, timeout=10)
                    assert model.map.value.state == "ready" and model.map.value.generation == generation
                    ui.wait_for(lambda: model.health.value.level is LinkLevel.OK)
                    # The key is still "held" (renewed above): the heart has run since the
                    # reconnect, and anything it sent has reached the simulator by the reply.
                    runner.sync()
                    runner.call(lambda: runner.session.client.request_once("getSafeDrive"))  # type: ignore[union-attr]
                    snap = sim2.snapshot()
                    assert snap.trans_ratio == 0 and snap.vel == 0
                    assert runner.lease.renew() is False
            finally:
                renewing.set()
                holder.join()
        finally:
            runner.close()


def test_lost_link_without_reconnect_is_shown_as_failed() -> None:
    with SimThread(sim_config()) as sim:
        runner, model, ui = connected_runner(sim.port, auto_reconnect=False)
        try:
            sim.kill()
            ui.wait_for(lambda: model.connection.value.phase is Phase.FAILED)
            assert model.connection.value.error_kind == "closed"
            assert model.health.value.level is LinkLevel.DOWN
        finally:
            runner.close()


def test_wrong_password_against_the_simulator(tmp_path: Path) -> None:
    users = tmp_path / "users.txt"
    users.write_text("UserInfoVersion1\nuser alice secret1 all\n")

    async def go() -> None:
        with SimThread(sim_config(users_path=users)) as sim:
            with pytest.raises(LoginRejected) as info:
                await AriaClient().connect(Target("127.0.0.1", sim.port, "alice", "nope"), timeout=5)
            assert info.value.reason == 1
            client = AriaClient()
            await client.connect(Target("127.0.0.1", sim.port, "alice", "secret1"), timeout=5)
            assert client.supports("ratioDrive")
            await client.disconnect()

    run(go())


@pytest.mark.parametrize("how", ["disconnect", "close"])
def test_disconnect_and_close_while_driving_send_zero_ratios_and_stop(how: str) -> None:
    """On a manual-clock simulator, so only our own stop can stop it (its watchdog never runs)."""
    with SimThread(sim_config(realtime=False)) as sim:
        clock = FakeClock()
        runner, _model, _ui = connected_runner(sim.port, clock=clock, fetch_map=False)
        try:
            runner.lease.grant(DriveRatios(100, 0, 50))
            runner.sync()
            eventually(lambda: sim.snapshot().trans_ratio == 100)
            if how == "disconnect":
                runner.disconnect().result(5)
            else:
                runner.close()
            eventually(lambda: sim.snapshot().mode_name == "stop", timeout=10)
            snap = sim.snapshot()
            assert snap.trans_ratio == 0 and snap.watchdog_stops == 0
            assert sim.call(lambda: sim.server.robot.received_ratios)[:3] == (0.0, 0.0, 0.0)  # type: ignore[union-attr]
        finally:
            runner.close()

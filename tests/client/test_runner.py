"""ClientRunner + Session over real sockets against a scripted server: model updates, lease, stale stop."""

from __future__ import annotations

import concurrent.futures
import time

import pytest

from rtmu.client.lease import DriveRatios
from rtmu.client.reconnect import Backoff
from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.model.observables import LinkLevel, Phase, RobotModel
from rtmu.protocol.payloads.drive import RatioDrive
from rtmu.values.target import Target

from .fakeclock import FakeClock
from .servers import MAP_LINES, ServerSide, ServerThread, TestServer, binary_map_packets
from .uiqueue import UiQueue, eventually


def ratio_drives(server: TestServer) -> list[RatioDrive]:
    return [RatioDrive.decode(r.args) for r in server.received if r.name == "ratioDrive"]


def drive_names(server: TestServer) -> list[str]:
    """What the server heard about motion (pings and other requests left out)."""
    return [n for n in server.names() if n in ("ratioDrive", "stop")]


@pytest.fixture
def server():  # type: ignore[no-untyped-def]
    with ServerThread(TestServer()) as srv:
        yield srv


def round_trip(runner: ClientRunner) -> None:
    """One request answered: what either side sent before it has now been read by the other."""
    runner.call(lambda: runner.session.client.request_once("getSafeDrive"))  # type: ignore[union-attr]


def dry_up_status(runner: ClientRunner, server: TestServer) -> None:
    """Stop the status stream (TCP stays up) and wait until no status is still on its way."""
    asked: list[int] = []
    server.handlers["updateNumbers"] = lambda s, a: asked.append(1)  # type: ignore[func-returns-value]
    eventually(lambda: bool(asked))  # the server's periodic task now sends nothing
    round_trip(runner)


def count_statuses(server: TestServer) -> list[int]:
    """Count the statuses the server sends from now on (same content as before)."""
    sent: list[int] = []
    answer = server.handlers["updateNumbers"]

    def counting(side: ServerSide, args: bytes) -> list[bytes] | None:
        sent.append(1)
        return answer(side, args)

    server.handlers["updateNumbers"] = counting
    return sent


def start(server: TestServer, clock=None, **config):  # type: ignore[no-untyped-def]
    model, ui = RobotModel(), UiQueue()
    runner = ClientRunner(model, post=ui.post, clock=clock or time.monotonic, config=SessionConfig(**config))
    runner.start()
    runner.connect(Target("127.0.0.1", server.port, profile="test")).result(5)
    ui.wait_for(lambda: model.connection.value.phase is Phase.CONNECTED and model.robot.value.status != "")
    return runner, model, ui


def test_connect_fills_the_model(server: TestServer) -> None:
    runner, model, ui = start(server)
    try:
        ui.wait_for(lambda: model.map.value.state == "ready" and model.robot.value.battery_low is not None)
        robot = model.robot.value
        assert (robot.x, robot.y, robot.th) == (1000.0, 2000.0, 90.0)
        assert robot.status == "Stopped" and robot.mode == "Stop" and robot.battery_v == 12.5
        assert robot.battery_low == 11.5 and robot.safe_drive is True and robot.temperature == 25
        conn = model.connection.value
        assert conn.profile == "test" and conn.supports("ratioDrive")
        assert model.map.value.name == "test.map"
        assert model.map.value.data.num_lines == 2  # type: ignore[attr-defined]
        ui.wait_for(lambda: model.health.value.rtt_ms is not None)
        assert model.health.value.level is LinkLevel.OK
    finally:
        runner.close()


def test_observers_hear_only_real_changes(server: TestServer) -> None:
    runner, model, ui = start(server, status_interval_ms=20)
    try:
        ui.wait_for(
            lambda: model.robot.value.battery_low is not None and model.robot.value.safe_drive is not None
        )
        changes: list[str] = []
        model.robot.observe(lambda old, new: changes.append("robot"))
        sent = count_statuses(server)
        eventually(lambda: len(sent) >= 5)  # five identical statuses…
        round_trip(runner)  # …all read by the client
        runner.sync()
        ui.drain()
        assert changes == []
        server.state["x"] = 1234
        ui.wait_for(lambda: model.robot.value.x == 1234.0)
        assert changes == ["robot"]
    finally:
        runner.close()


def test_hold_lapse_and_release_with_a_fake_clock(server: TestServer) -> None:
    clock = FakeClock()
    # Status every 1 s: the link stays "fresh" for 3 s of fake time without real waiting.
    runner, _model, _ui = start(server, clock=clock, status_interval_ms=1000)
    try:
        runner.lease.grant(DriveRatios(100, 0, 40))
        runner.sync()
        eventually(lambda: ratio_drives(server)[-1:] == [RatioDrive(100, 0, 40)])
        n = len(ratio_drives(server))
        for _ in range(5):  # held: renewed by the UI every 100 ms of (fake) time
            clock.advance(0.1)
            assert runner.lease.renew()
            runner.sync()
        eventually(lambda: len(ratio_drives(server)) == n + 5)
        # The UI freezes: 0.35 s without renewal.
        clock.advance(0.35)
        runner.sync()
        eventually(lambda: drive_names(server)[-1] == "stop")
        assert ratio_drives(server)[-1] == RatioDrive(0, 0, 0)
        assert len(ratio_drives(server)) == n + 6
        assert runner.lease.renew() is False
        # A fresh grant drives again; releasing sends zeros and stop once.
        stops = drive_names(server).count("stop")
        runner.lease.grant(DriveRatios(0, 100, 40))
        runner.sync()
        runner.lease.release()
        runner.sync()
        eventually(lambda: drive_names(server).count("stop") == stops + 1)
        assert drive_names(server)[-3:] == ["ratioDrive", "ratioDrive", "stop"]
        assert ratio_drives(server)[-2:] == [RatioDrive(0, 100, 40), RatioDrive(0, 0, 0)]
    finally:
        runner.close()


def test_stale_status_stops_the_robot_even_while_the_lease_is_renewed(server: TestServer) -> None:
    clock = FakeClock()
    runner, model, ui = start(server, clock=clock)
    try:
        runner.lease.grant(DriveRatios(100, 0, 50))
        runner.sync()
        dry_up_status(runner, server)
        for _ in range(5):  # a new link's limit is the ceiling, 0.45 s (base.link_timing)
            clock.advance(0.1)
            runner.lease.renew()
            runner.sync()
        eventually(lambda: drive_names(server)[-1] == "stop")
        ui.wait_for(lambda: model.health.value.level is LinkLevel.STALE)
        assert runner.lease.renew() is False
    finally:
        runner.close()


def test_stop_is_sent_even_when_the_link_looks_stale(server: TestServer) -> None:
    clock = FakeClock()
    runner, model, ui = start(server, clock=clock)
    try:
        dry_up_status(runner, server)
        clock.advance(1.0)
        runner.sync()
        ui.wait_for(lambda: model.health.value.level is LinkLevel.STALE)
        before = server.names().count("stop")
        runner.stop()
        runner.sync()
        eventually(lambda: server.names().count("stop") == before + 1)
    finally:
        runner.close()


def test_disconnect_clears_the_model(server: TestServer) -> None:
    runner, model, ui = start(server)
    try:
        runner.disconnect().result(5)
        ui.wait_for(lambda: model.connection.value.phase is Phase.DISCONNECTED)
        assert model.robot.value.status == ""
        assert model.health.value.level is LinkLevel.DOWN
    finally:
        runner.close()


def test_connect_failure_is_shown_in_the_model() -> None:
    model, ui = RobotModel(), UiQueue()
    with ClientRunner(model, post=ui.post) as runner:
        with pytest.raises(Exception):  # noqa: B017 -- the model is what we check
            runner.connect(Target("127.0.0.1", 1, profile="x")).result(5)
        ui.wait_for(lambda: model.connection.value.phase is Phase.FAILED)
        assert model.connection.value.error_kind == "refused"
        assert "refused" in model.connection.value.error


def test_lost_link_reconnects_and_comes_back_without_motion(server: TestServer) -> None:
    clock = FakeClock()
    runner, model, ui = start(server, clock=clock, backoff=lambda: Backoff(initial=0.01, jitter=0.0))
    try:
        runner.lease.grant(DriveRatios(100, 0, 50))
        runner.sync()
        seen: list[tuple[Phase, str]] = []
        model.connection.observe(lambda old, new: seen.append((new.phase, new.error)))
        dry_up_status(runner, server)  # TCP stays up, the status stops
        clock.advance(2.5)
        runner.sync()
        ui.wait_for(lambda: any(p is Phase.RECONNECTING and "no status" in e for p, e in seen))
        ui.wait_for(lambda: model.connection.value.phase is Phase.CONNECTED)
        assert len(server.sides) == 2  # a new connection
        drives = len(ratio_drives(server))
        assert runner.lease.renew() is False
        runner.sync()
        round_trip(runner)  # anything the heart sent has reached the server by now
        assert len(ratio_drives(server)) == drives  # nothing resumed
    finally:
        runner.close()


def test_disconnect_while_logging_in_cancels_the_attempt() -> None:
    model, ui = RobotModel(), UiQueue()
    config = SessionConfig(connect_timeout=600)  # only a cancel can end this attempt during the test
    with (
        ServerThread(TestServer(silent=True)) as server,
        ClientRunner(model, post=ui.post, config=config) as runner,
    ):
        attempt = runner.connect(Target("127.0.0.1", server.port))
        ui.wait_for(lambda: model.connection.value.phase is Phase.CONNECTING)
        runner.disconnect().result(5)
        ui.wait_for(lambda: model.connection.value.phase is Phase.DISCONNECTED)
        concurrent.futures.wait([attempt], timeout=5)
        assert attempt.done()
        assert attempt.cancelled() or attempt.exception() is not None
        runner.sync()  # whatever the cancelled attempt still published has been posted
        ui.drain()
        assert model.connection.value.phase is Phase.DISCONNECTED


def test_a_storm_of_map_updates_costs_one_more_download_not_hundreds() -> None:
    server_obj = TestServer()
    withheld: list[ServerSide] = []

    def maps(side: ServerSide, args: bytes) -> list[bytes] | None:
        if not withheld:
            withheld.append(side)  # the first download hangs until the storm has been sent
            return None
        return binary_map_packets(MAP_LINES)

    def storm_then_answer() -> None:
        side = withheld[0]
        for _ in range(200):
            server_obj.broadcast("mapUpdated")
        for payload in binary_map_packets(MAP_LINES):  # then the first download completes
            side.conn.send_data("getMapBinary", payload)
        side.writer.write(side.conn.data_to_send())

    server_obj.handlers["getMapBinary"] = maps
    thread = ServerThread(server_obj)
    with thread as server:
        runner, model, ui = start(server)
        try:
            eventually(lambda: bool(withheld))
            thread.call(storm_then_answer)
            ui.wait_for(lambda: model.map.value.state == "ready" and model.map.value.generation == 2)
            runner.sync()
            assert server.names().count("getMapBinary") == 2
            assert runner.call(lambda: len(runner.session._tasks)) <= 3  # type: ignore[union-attr]
        finally:
            runner.close()


def test_unanswered_pings_make_the_rtt_unknown_stop_driving_and_recover(server: TestServer) -> None:
    clock = FakeClock()  # the status stays fresh: only the pings can spoil the link
    runner, model, ui = start(server, clock=clock, ping_interval=0.02, ping_timeout=0.1)
    try:
        ui.wait_for(lambda: model.health.value.rtt_ms is not None)
        runner.lease.grant(DriveRatios(100, 0, 50))
        runner.sync()
        eventually(lambda: drive_names(server)[-1:] == ["ratioDrive"])
        answer = server.handlers["getSafeDrive"]
        server.handlers["getSafeDrive"] = lambda s, a: None  # status goes on, pings go unanswered
        ui.wait_for(lambda: model.health.value.level is LinkLevel.STALE)
        assert model.health.value.rtt_ms is None and model.health.value.ping_failures >= 1
        eventually(lambda: drive_names(server)[-1] == "stop")
        assert runner.lease.renew() is False
        server.handlers["getSafeDrive"] = answer
        ui.wait_for(
            lambda: model.health.value.level is LinkLevel.OK and model.health.value.rtt_ms is not None
        )
        assert model.connection.value.phase is Phase.CONNECTED
    finally:
        runner.close()


def test_a_server_that_stops_reading_is_stale_then_lost(server: TestServer) -> None:
    clock = FakeClock()
    runner, model, ui = start(server, clock=clock, ping_interval=0.02, ping_timeout=0.1)
    try:
        ui.wait_for(lambda: model.health.value.rtt_ms is not None)
        runner.lease.grant(DriveRatios(100, 0, 50))
        runner.sync()
        seen: list[tuple[Phase, str]] = []
        model.connection.observe(lambda old, new: seen.append((new.phase, new.error)))
        levels: list[LinkLevel] = []
        model.health.observe(lambda old, new: levels.append(new.level))
        server.deafen()
        ui.wait_for(lambda: any(p is Phase.RECONNECTING and "pings" in e for p, e in seen))
        assert LinkLevel.STALE in levels
        assert runner.lease.renew() is False  # driving stopped on the first unanswered ping
    finally:
        runner.close()


def test_connecting_again_while_driving_stops_the_robot_on_the_old_link_first(server: TestServer) -> None:
    runner, model, ui = start(server)
    try:
        runner.lease.grant(DriveRatios(100, 0, 50))
        runner.sync()
        eventually(lambda: drive_names(server)[-1:] == ["ratioDrive"])
        runner.connect(Target("127.0.0.1", server.port, profile="other")).result(5)
        ui.wait_for(
            lambda: (
                model.connection.value.phase is Phase.CONNECTED and model.connection.value.profile == "other"
            )
        )
        eventually(lambda: "SHUTDOWN" in [r.name for r in server.received if r.side == 0], timeout=10)
        old = [r for r in server.received if r.side == 0 and r.name in ("ratioDrive", "stop", "SHUTDOWN")]
        assert [r.name for r in old[-3:]] == ["ratioDrive", "stop", "SHUTDOWN"]
        assert RatioDrive.decode(old[-3].args) == RatioDrive(0, 0, 0)
        assert not any(r.name == "ratioDrive" for r in server.received if r.side == 1)  # nothing resumed
    finally:
        runner.close()


def test_run_blocking_runs_off_the_ui_and_network_threads_and_answers_on_the_ui_thread() -> None:
    import threading

    model, ui = RobotModel(), UiQueue()
    with ClientRunner(model, post=ui.post) as runner:
        ran_on: list[int] = []
        answers: list[tuple[object, int]] = []

        def lookup() -> str:
            ran_on.append(threading.get_ident())
            return "secret1"

        def failing() -> str:
            raise RuntimeError("the keyring is locked")

        runner.run_blocking(lookup, lambda r: answers.append((r, threading.get_ident())))
        runner.run_blocking(failing, lambda r: answers.append((r, threading.get_ident())))
        ui.wait_for(lambda: len(answers) == 2)
        network = runner._thread.ident
        assert ran_on and ran_on[0] not in (threading.get_ident(), network)
        assert answers == [("secret1", threading.get_ident()), (None, threading.get_ident())]


def test_a_lease_granted_while_reconnecting_is_ended_when_the_link_comes_back() -> None:
    clock = FakeClock()  # the grant stays "fresh" for as long as the test likes
    thread = ServerThread(TestServer())
    with thread as server:
        runner, model, ui = start(server, clock=clock, backoff=lambda: Backoff(initial=0.01, jitter=0.0))
        try:
            server.hold_logins()
            thread.call(lambda: server.kill(server.sides[0]))
            ui.wait_for(lambda: model.connection.value.phase is Phase.RECONNECTING)
            eventually(lambda: len(server.sides) == 2)  # the next attempt waits at the server's door
            runner.lease.grant(DriveRatios(100, 0, 50))  # a grant slips in meanwhile (no controller)
            runner.sync()
            server.admit_logins()
            ui.wait_for(lambda: model.connection.value.phase is Phase.CONNECTED)
            runner.sync()
            runner.call(lambda: runner.session.client.request_once("getSafeDrive"))  # type: ignore[union-attr]
            assert not [r for r in server.received if r.side == 1 and r.name == "ratioDrive"]
            assert runner.lease.renew() is False
        finally:
            runner.close()


def test_loop_lag_shows_a_blocked_network_loop() -> None:
    import threading

    clock = FakeClock()
    runner = ClientRunner(clock=clock)
    assert runner.loop_lag() is None  # not started
    runner.start()
    try:
        eventually(lambda: runner.loop_lag() == 0.0)
        release, blocked = threading.Event(), threading.Event()

        def block_the_loop() -> None:  # slow work on the loop: exactly what must never happen
            blocked.set()
            release.wait(5)

        runner.submit(block_the_loop)
        assert blocked.wait(5)
        clock.advance(1.5)
        assert runner.loop_lag() == 1.5  # working, not waiting, since the block began
        release.set()
        eventually(lambda: runner.loop_lag() == 0.0)  # waiting again once the handler returned
    finally:
        runner.close()
    assert runner.loop_lag() is None


def test_a_loop_waiting_long_for_the_network_has_no_lag_and_no_timer_of_the_runners() -> None:
    """Waiting is no lag, however long: the lag is read off the loop's selector, and nothing the
    runner scheduled wakes a loop that has nothing to do (a heartbeat woke it 10 times a second)."""
    import threading

    clock = FakeClock()
    runner = ClientRunner(clock=clock)
    runner.start()
    try:
        eventually(lambda: runner.loop_lag() == 0.0)
        clock.advance(60.0)
        assert runner.loop_lag() == 0.0
        scheduled: list[object] = []
        done = threading.Event()

        def look() -> None:
            timers = runner.loop._scheduled  # type: ignore[attr-defined]
            scheduled.extend(h._callback for h in timers if not h.cancelled())
            done.set()

        runner.loop.call_soon_threadsafe(look)
        assert done.wait(30)
        owners = [getattr(callback, "__self__", None) for callback in scheduled]
        assert runner not in owners, f"the runner keeps a timer: {scheduled}"
    finally:
        runner.close()


def test_stop_and_wait_returns_once_the_stop_has_left(server: TestServer) -> None:
    runner, _model, _ui = start(server)
    try:
        runner.lease.grant(DriveRatios(100, 0, 50))
        runner.sync()
        eventually(lambda: drive_names(server)[-1:] == ["ratioDrive"])
        assert runner.stop_and_wait(1.0) is True
        assert runner.lease.renew() is False
        eventually(lambda: drive_names(server)[-2:] == ["ratioDrive", "stop"])
        assert ratio_drives(server)[-1] == RatioDrive(0, 0, 0)
    finally:
        runner.close()
    assert runner.stop_and_wait(0.1) is False  # closed: nothing to send it with


def test_a_link_lost_while_driving_is_reconnected_at_once_and_the_first_thing_sent_is_a_stop() -> None:
    """Our connection dropped under a driving robot (the guardian's link may have gone with it):
    the session does not wait out its backoff, and zero ratios and a stop go out before anything."""
    server = TestServer()
    thread = ServerThread(server)
    with thread:
        runner, model, ui = start(server, backoff=lambda: Backoff(initial=30.0, jitter=0.0))
        try:
            runner.lease.grant(DriveRatios(60, 0, 50))
            runner.sync()
            eventually(lambda: ratio_drives(server)[-1:] == [RatioDrive(60, 0, 50)])
            thread.call(lambda: server.kill(server.sides[0]))
            eventually(lambda: len(server.sides) == 2, timeout=5.0)  # at once, not after 30 s
            eventually(lambda: any(r.side == 1 and r.name == "stop" for r in server.received))
            on_new = [r.name for r in server.received if r.side == 1 and r.name in ("ratioDrive", "stop")]
            assert on_new[:2] == ["ratioDrive", "stop"]
            first = next(r for r in server.received if r.side == 1 and r.name == "ratioDrive")
            assert RatioDrive.decode(first.args) == RatioDrive(0, 0, 0)
            ui.wait_for(lambda: model.connection.value.phase is Phase.CONNECTED)
            assert not runner.lease.view().live  # and nothing drives until a fresh press
        finally:
            runner.close()

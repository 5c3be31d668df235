"""Malformed data from a server: a typed one-line failure or a counted drop; never a hang or a traceback."""

from __future__ import annotations

from pathlib import Path

import pytest

from patience import cli_timeout
from rtmu.base.exit_codes import EXIT_CONNECTION
from rtmu.cli import main
from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.model.observables import Phase, RobotModel
from rtmu.values.target import Target

from .servers import MAP_LINES, ServerThread, TestServer
from .uiqueue import UiQueue

BAD_HEADER_MAP = ["2D-Map", "NumPoints: many", *MAP_LINES[4:]]


Connected = tuple[ClientRunner, RobotModel, UiQueue, list[tuple[str, str]]]


def _connected(server: TestServer, **config: object) -> Connected:
    model, ui = RobotModel(), UiQueue()
    runner = ClientRunner(model, post=ui.post, config=SessionConfig(**config))  # type: ignore[arg-type]
    notices: list[tuple[str, str]] = []
    runner.on_notice = lambda notice: notices.append((notice.level.value, notice.text))
    runner.start()
    runner.connect(Target("127.0.0.1", server.port)).result(5)
    ui.wait_for(lambda: model.connection.value.phase is Phase.CONNECTED)
    return runner, model, ui, notices


@pytest.mark.parametrize("binary", [True, False])
def test_a_map_with_a_bad_header_ends_as_failed_with_the_reason(binary: bool) -> None:
    specs = None
    if not binary:
        from .servers import SPECS

        specs = [row for row in SPECS if row[0] != "getMapBinary"]
    with ServerThread(TestServer(specs, map_lines=BAD_HEADER_MAP)) as server:
        runner, model, ui, notices = _connected(server)
        try:
            ui.wait_for(lambda: model.map.value.state == "failed")
            assert "NumPoints" in model.map.value.error and "malformed" in model.map.value.error
            ui.wait_for(lambda: any("map could not be loaded" in text for _, text in notices))
            assert model.connection.value.phase is Phase.CONNECTED  # the link itself is fine
        finally:
            runner.close()


def test_garbage_binary_blocks_end_as_failed() -> None:
    server_obj = TestServer()

    def broken(side, args):  # type: ignore[no-untyped-def]
        # header, LINES, then a block whose length is not a whole number of segments
        return [b"2D-Map\x00", b"LINES\x00", b"\x01\x02\x03", b""]

    server_obj.handlers["getMapBinary"] = broken
    with ServerThread(server_obj) as server:
        runner, model, ui, _notices = _connected(server)
        try:
            ui.wait_for(lambda: model.map.value.state == "failed")
            assert model.map.value.error
        finally:
            runner.close()


@pytest.mark.parametrize("extra", [[], ["--text"]])
def test_rtmu_map_with_a_bad_map_exits_3_with_one_line(
    extra: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "x.map"
    with ServerThread(TestServer(map_lines=BAD_HEADER_MAP)) as server:
        code = main(
            ["map", f"127.0.0.1:{server.port}", "--out", str(out), "--timeout", cli_timeout(5), *extra]
        )
    err = capsys.readouterr().err
    assert code == EXIT_CONNECTION
    assert err.count("\n") == 1 and err.startswith("rtmu map: ") and "NumPoints" in err
    assert not out.exists()


def _bad_status_server() -> TestServer:
    server = TestServer()
    server.handlers["updateNumbers"] = lambda s, a: [b"\x01"]  # one byte of a 19-byte status
    return server


@pytest.mark.parametrize(
    "args",
    [
        ["status", "--once"],
        ["status", "--count", "2", "--interval", "20"],
        ["drive", "--trans", "30", "--seconds", "0.2"],  # outside ARIA's dead zone: no warning line
    ],
)
def test_a_malformed_status_exits_3_with_one_line(
    args: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    with ServerThread(_bad_status_server()) as server:
        code = main([args[0], f"127.0.0.1:{server.port}", *args[1:], "--timeout", "0.5"])
    err = capsys.readouterr().err
    assert code == EXIT_CONNECTION, err
    assert err.count("\n") == 1 and err.startswith(f"rtmu {args[0]}: ") and "malformed" in err
    assert "Traceback" not in err


def test_a_bad_status_packet_is_counted_and_the_session_goes_on() -> None:
    from .fakeclock import FakeClock

    sent = [0]
    server_obj = TestServer()

    def every_other_bad(side, args):  # type: ignore[no-untyped-def]
        sent[0] += 1
        if sent[0] % 2 == 0:
            return [b"\x01"]
        server_obj.state["x"] = sent[0]
        from .servers import _numbers

        return [_numbers(server_obj.state)]

    server_obj.handlers["updateNumbers"] = every_other_bad
    with ServerThread(server_obj) as server:
        model, ui = RobotModel(), UiQueue()
        runner = ClientRunner(
            model, post=ui.post, clock=FakeClock(), config=SessionConfig(status_interval_ms=20)
        )
        runner.start()
        try:
            runner.connect(Target("127.0.0.1", server.port)).result(5)
            ui.wait_for(lambda: model.connection.value.phase is Phase.CONNECTED)
            ui.wait_for(lambda: model.health.value.dropped >= 3 and model.robot.value.x >= 7)
            runner.sync()
            ui.drain()
            assert model.connection.value.phase is Phase.CONNECTED
            assert runner.call(lambda: runner.session.client.connected)  # type: ignore[union-attr]
        finally:
            runner.close()

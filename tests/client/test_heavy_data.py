"""The heaviest well-formed data a server may send must not take driving away.

Against the scripted servers of ``heavy_servers`` (real loopback sockets): 256 drawings of 3 998
points resent every millisecond (from a process of its own, as a robot's server is: in this one its
flood took the client's interpreter lock, and on a loaded machine delayed its own status past the
link's limit), a popup storm, and 632-byte pictures that declare 4096×4096 pixels.
A held drive is never stopped by them and ``ratioDrive`` keeps flowing; what reaches the window is
bounded (points per state, states per second, decoded picture size). Rates are not timed here —
``bench/bench_heavy.py`` measures them — only counted with generous bounds.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
import pytest

from rtmu.client.drawing_budget import MAX_SHOWN_POINTS, sample_array, thin
from rtmu.client.drawings_feed import DrawingsFeed
from rtmu.client.errors import MalformedReply
from rtmu.client.lease import DriveRatios
from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.model.observables import RobotModel
from rtmu.protocol.payloads.drawings import DrawingPoints
from rtmu.values.target import Target

from .heavy_servers import FloodProcess, big_jpeg, drawing_flood_server, popup_storm_server
from .servers import ServerThread, TestServer
from .uiqueue import UiQueue

HOLD = 3.0


def received_drives(server: TestServer) -> Callable[[], int]:
    """How many ``ratioDrive`` an in-process server has heard so far."""
    return lambda: len([r for r in server.received if r.name == "ratioDrive"])


def hold_a_drive(
    port: int, heard: Callable[[], int]
) -> tuple[ClientRunner, RobotModel, UiQueue, list[str], int]:
    """Connect, hold a drive for HOLD s renewing it as the window's timer does; (…, stops, drives):
    ``heard()`` counts the ``ratioDrive`` the server has heard."""
    model, ui = RobotModel(), UiQueue()
    runner = ClientRunner(model, post=ui.post, config=SessionConfig(fetch_map=False))
    stops: list[str] = []
    runner.on_stop = lambda reason, sent: stops.append(reason)
    runner.start()
    runner.connect(Target("127.0.0.1", port)).result(10)
    ui.wait_for(lambda: model.health.value.rtt_ms is not None, timeout=10)
    runner.lease.grant(DriveRatios(30, 0, 30))
    before = heard()
    end = time.monotonic() + HOLD
    while time.monotonic() < end:
        runner.lease.renew()
        ui.drain()
        time.sleep(0.04)
    drives = heard() - before
    stopped = list(stops)  # before our own release's stop
    runner.lease.release()
    return runner, model, ui, stopped, drives


def test_a_drawing_flood_neither_stops_a_held_drive_nor_swamps_the_window() -> None:
    server = FloodProcess("drawings")
    try:
        runner, model, _ui, stops, drives = hold_a_drive(server.port, lambda: len(server.since("drive", 0.0)))
        try:
            assert runner.session is not None
            feed = runner.session.feed(DrawingsFeed)
            shown = model.drawings.value.layers
            assert stops == [], stops
            assert drives >= HOLD * 10 / 2, f"{drives} ratioDrive in {HOLD} s"  # 10 Hz, generously
            assert feed.samples > 20 * HOLD * 10  # a real flood came…
            assert sum(len(d.points) for d in shown) <= MAX_SHOWN_POINTS  # …the window got a budget
            assert len(shown) == 256 and all(d.total_points == 3998 for d in shown if d.points)
        finally:
            runner.close()
    finally:
        server.close()


def test_a_popup_storm_neither_stops_a_held_drive_nor_floods_the_ui_thread() -> None:
    server = popup_storm_server()
    with ServerThread(server):
        changes: list[int] = []
        runner, model, ui, stops, drives = hold_a_drive(server.port, received_drives(server))
        try:
            model.popups.observe(lambda old, new: changes.append(1))
            sent = server.sent
            end = time.monotonic() + 1.0
            while time.monotonic() < end:
                ui.drain()
                time.sleep(0.02)
            assert stops == [] and drives >= HOLD * 10 / 2, (stops, drives)
            assert server.sent - sent > 50  # ~200 a second came
            assert len(changes) <= 1.0 / 0.1 + 2  # the UI thread heard at most ~10 a second
            assert model.popups.value.dropped > 0 and len(model.popups.value.open) == 64
        finally:
            runner.close()


def test_thinning_keeps_small_drawings_whole_and_segments_in_pairs() -> None:
    big = np.arange(8000, dtype=np.int32).reshape(-1, 2)  # 4000 points
    small = np.arange(20, dtype=np.int32).reshape(-1, 2)
    out = thin({"a": ("polyDots", big), "b": ("polySegments", big), "c": ("polyLine", small)}, budget=1000)
    assert out["c"] == tuple(map(tuple, small.tolist()))  # whole
    assert len(out["a"]) + len(out["b"]) + len(out["c"]) <= 1000 and len(out["a"]) > 400
    seg = np.array(out["b"]).reshape(-1, 2, 2)
    assert (seg[:, 1] - seg[:, 0] == 2).all()  # every kept segment is a real (start, end) pair
    assert thin({"a": ("polyDots", big)}, budget=10_000)["a"][-1] == (7998, 7999)  # under budget: all


def test_a_sample_that_lies_about_its_count_is_refused_in_the_decoders_words() -> None:
    good = DrawingPoints(((1, 2), (3, 4))).encode()
    assert sample_array("laser", good).tolist() == [[1, 2], [3, 4]]
    lying = (1_000_000).to_bytes(4, "little") + good[4:]
    with pytest.raises(MalformedReply, match="malformed 'laser' drawing"):
        sample_array("laser", lying)


def test_a_tiny_jpeg_that_declares_4096_squared_is_decoded_small() -> None:
    pytest.importorskip("gi")
    from rtmu.ui.camera import DECODE_SIDE, decode_jpeg

    jpeg = big_jpeg(4096)
    assert len(jpeg) == 632
    decoded = decode_jpeg(jpeg)
    assert decoded.width == decoded.height == DECODE_SIDE  # 1/4 scale: 3 MB, not 50 MB
    assert len(decoded.rgb) == DECODE_SIDE * DECODE_SIDE * 3


def test_the_flood_server_really_varies_its_samples() -> None:
    """(So that skipping a sample seen before cannot be what keeps the client fast.)"""
    server = drawing_flood_server(count=1)
    a = server.handlers["flood000"](None, b"")[0]  # type: ignore[arg-type]
    b = server.handlers["flood000"](None, b"")[0]  # type: ignore[arg-type]
    assert a != b and len(a) == len(b) == 4 + 8 * 3998

"""The real window against the heaviest well-formed data a server may send: it still drives.

The server is one of ``tests/client/heavy_servers.py`` in a process of its own (so its flood never
shares this process's interpreter lock with the window), reporting every drive packet it hears.
For each flood: Up held through real X input keeps ``ratioDrive`` coming with no stop, a release
stops the robot, and what reached the window is bounded (points drawn, popup rebuilds; a frame
declaring 4096×4096 with 632 bytes of data is refused unread). Rates and latencies are measured
in ``bench/bench_heavy.py``.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from client.heavy_servers import FloodProcess
from rtmu.client.drawing_budget import MAX_SHOWN_POINTS
from rtmu.client.video_session import CameraFeed

from .harness import Gui, idle, pump

HOLD = 3.0


@pytest.fixture
def flood(request: pytest.FixtureRequest, screenshots: Path) -> Iterator[tuple[Gui, FloodProcess]]:
    server = FloodProcess(request.param)
    try:
        gui = Gui.start(screenshots, request.node.name, "127.0.0.1", server.port)
        try:
            yield gui, server
        finally:
            gui.xdotool("keyup", "Up")
            gui.close()
    finally:
        server.close()


def _hold_up(gui: Gui, server: FloodProcess) -> tuple[int, int]:
    """Hold Up for HOLD s (pressing again until the window drives): (drives heard, stops heard)."""
    for _attempt in range(5):
        gui.keydown("Up")
        t0 = time.monotonic()
        try:
            pump(lambda t0=t0: bool(server.since("drive", t0)), 3, "the first ratioDrive")  # type: ignore[misc]
            break
        except AssertionError:
            gui.keyup("Up")
    start = time.monotonic()
    idle(HOLD)
    return len(server.since("drive", start)), len(server.since("stop", start))


def _release_stops(gui: Gui, server: FloodProcess) -> None:
    up = time.monotonic()
    gui.keyup("Up")
    pump(lambda: bool(server.since("stop", up)), 5, "the release to stop the robot")


@pytest.mark.parametrize("flood", ["drawings"], indirect=True)
def test_a_drawing_flood_leaves_the_window_driving(flood: tuple[Gui, FloodProcess]) -> None:
    gui, server = flood
    pump(lambda: len(gui.model.drawings.value.layers) == 256, 10, "the 256 drawings listed")
    pump(lambda: any(d.points for d in gui.model.drawings.value.layers), 10, "drawings to arrive")
    drives, stops = _hold_up(gui, server)
    gui.shot("drawing-flood-driving")
    assert stops == 0 and drives >= HOLD * 10 / 2, (drives, stops)
    assert sum(len(d.points) for d in gui.model.drawings.value.layers) <= MAX_SHOWN_POINTS
    _release_stops(gui, server)


@pytest.mark.parametrize("flood", ["popups"], indirect=True)
def test_a_popup_storm_leaves_the_window_driving(flood: tuple[Gui, FloodProcess]) -> None:
    gui, server = flood
    stack = gui.window.popup_stack
    pump(lambda: gui.model.popups.value.dropped > 0, 10, "the storm to overflow the kept popups")
    rebuilds = stack.rebuilds
    drives, stops = _hold_up(gui, server)
    gui.shot("popup-storm-driving")
    assert stops == 0 and drives >= HOLD * 10 / 2, (drives, stops)
    assert stack.rebuilds - rebuilds <= HOLD * 10 + 5  # ~10 a second at most, not ~200
    _release_stops(gui, server)


@pytest.mark.parametrize("flood", ["frames"], indirect=True)
def test_4096_squared_frames_leave_the_window_driving(flood: tuple[Gui, FloodProcess]) -> None:
    gui, server = flood
    gui.key("v")  # live video: one 632-byte frame declaring 4096×4096 after another
    session = gui.window.session.runner.session
    assert session is not None
    camera_feed = session.feed(CameraFeed)

    def refused() -> int:
        feed = camera_feed.feed
        return 0 if feed is None else feed.stats.dropped

    # Its data cannot fill what it declares (client.jpeg_bounds): refused on arrival, never decoded.
    pump(lambda: refused() >= 5, 10, "the frames to be asked for and refused")
    drives, stops = _hold_up(gui, server)
    gui.shot("big-frames-driving")
    assert stops == 0 and drives >= HOLD * 10 / 2, (drives, stops)
    assert gui.window.camera.texture is None and refused() >= 20  # still asked for, still refused
    _release_stops(gui, server)

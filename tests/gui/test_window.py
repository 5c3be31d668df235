"""The real window against the real simulator, with real key presses through the X server.

Each test leaves PNGs of the window in the screenshot folder the run prints.
Motion is real time (the simulator runs on its own clock); every wait has a
timeout, and what is checked is the simulator's own state, not the window's
idea of it.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from rtmu.model.observables import Phase
from rtmu.sim import SimConfig, SimThread
from simulators import simulator

from .harness import OFFICE_MAP, Gui, LoopProbe, idle, pump

sim = simulator(map_path=OFFICE_MAP, camera=True, seed=1)


def received(sim: SimThread) -> tuple[float, float, float, float] | None:
    """The last ratioDrive the simulator received (trans, rot, throttle, lat)."""
    return sim.call(lambda: sim.server.robot.received_ratios)


def moving(sim: SimThread) -> bool:
    return abs(sim.snapshot().vel) > 1.0


def stopped(sim: SimThread) -> bool:
    snap = sim.snapshot()
    return abs(snap.vel) < 1e-6 and abs(snap.rot_vel) < 1e-6 and snap.trans_ratio == 0


def dark(pixels: np.ndarray, x: float, y: float, radius: int = 2) -> bool:
    """A map-wall-dark pixel near (x, y)."""
    xi, yi = round(x), round(y)
    patch = pixels[max(0, yi - radius) : yi + radius + 1, max(0, xi - radius) : xi + radius + 1].astype(int)
    return bool((patch.sum(axis=2) < 3 * 90).any())


def robot_blue(pixels: np.ndarray, x: float, y: float, radius: int = 2) -> bool:
    xi, yi = round(x), round(y)
    patch = pixels[max(0, yi - radius) : yi + radius + 1, max(0, xi - radius) : xi + radius + 1].astype(int)
    r, g, b = patch[..., 0], patch[..., 1], patch[..., 2]
    return bool(((b > 170) & (r < 90) & (b - g > 60)).any())


# -- connect and draw -------------------------------------------------------------------------------


def test_connects_and_draws_the_map_walls_and_the_robot_where_the_simulator_has_it(
    gui: Gui, sim: SimThread
) -> None:
    gui.shot("connected")
    pixels = gui.stage_pixels()
    vp = gui.stage.viewport
    data = gui.model.map.value.data
    # A known wall: every segment of the office map is a wall; sample along the first ten.
    hits = 0
    tried = 0
    for x0, y0, x1, y1 in np.asarray(data.segments)[:10].tolist():
        for t in (0.3, 0.5, 0.7):
            sx, sy = vp.to_screen(x0 + t * (x1 - x0), y0 + t * (y1 - y0))
            if 3 <= sx < vp.width - 3 and 3 <= sy < vp.height - 3:
                tried += 1
                hits += dark(pixels, sx, sy)
    assert tried >= 10 and hits >= 0.8 * tried, f"{hits}/{tried} wall samples are dark"
    # Empty floor is not dark: the middle of the corridor.
    sx, sy = vp.to_screen(8000, 6000)
    assert not dark(pixels, sx, sy, radius=0)
    # The robot, drawn where the simulator says it is (a point on its body behind the heading mark).
    snap = sim.snapshot()
    th = math.radians(snap.th)
    sx, sy = vp.to_screen(snap.x - 120 * math.cos(th), snap.y - 120 * math.sin(th))
    assert robot_blue(pixels, sx, sy), "no fresh (blue) robot at the simulator's pose"
    # The toolbar shows the same pose, fresh.
    assert gui.window.toolbar.cells["x"].value.get_text() == f"{snap.x / 1000:.2f}"
    assert not gui.window.toolbar.cells["x"].stale


# -- driving with real keys ---------------------------------------------------------------------------


def test_holding_up_drives_forward_and_releasing_stops(gui: Gui, sim: SimThread) -> None:
    start = sim.snapshot()
    timers = gui.window.timers
    assert not timers.fast_running, "a window at rest runs no lease tick and no guardian beat"
    gui.keydown("Up")
    try:
        pump(lambda: sim.snapshot().x > start.x + 150, 8, "the robot to drive 150 mm forward")
        assert received(sim)[0] > 0  # type: ignore[index]
        assert timers.fast_running, "a held drive renews its lease and beats for the guardian"
        gui.shot("driving")
    finally:
        gui.keyup("Up")
    pump(lambda: stopped(sim), 8, "the robot to stop after the key was released")
    assert gui.window.controller.held == frozenset()
    pump(lambda: not timers.fast_running, 10, "the drive's timers to end once the guardian is disarmed")
    gui.shot("released")


def test_a_still_robot_draws_no_new_frame(gui: Gui, sim: SimThread) -> None:
    """Status keeps coming at 10 Hz while the robot stands: an unchanged frame is never drawn again."""
    stage = gui.stage
    pump(lambda: stopped(sim) and stage.last_frame_complete, 10, "a still robot on a drawn map")
    idle(1.0)  # the first status of a still robot, the tiles: drawn by now
    frames = stage.frames
    idle(2.0)
    assert stage.frames == frames, f"{stage.frames - frames} frames redrawn for a robot that did not move"
    gui.shot("still")


def test_the_red_stop_in_the_header_stops_the_robot_while_a_drive_key_is_held(
    gui: Gui, sim: SimThread
) -> None:
    window = gui.window
    stop = window.stop_button
    assert stop.get_mapped() and stop.has_css_class("destructive-action"), "STOP is on screen, in red"
    assert not window.connect_button.has_css_class("destructive-action"), "only STOP is red"
    gui.keydown("Up")
    try:
        pump(lambda: moving(sim), 8, "the robot to move")
        assert sim.call(lambda: sim.server.robot.mode_name) == "ratioDrive"
        gui.click(stop)
        pump(lambda: sim.call(lambda: sim.server.robot.mode_name) == "stop", 3, "the simulator to get stop")
        pump(lambda: stopped(sim), 8, "the robot to stop")
        idle(0.6)  # the key is still down: it stays blocked until let go
        assert stopped(sim)
        gui.shot("stopped-by-the-header-button")
    finally:
        gui.keyup("Up")


def test_space_stops_even_while_a_drive_key_is_still_held(gui: Gui, sim: SimThread) -> None:
    gui.keydown("Up")
    try:
        pump(lambda: moving(sim), 8, "the robot to move")
        gui.key("space")
        pump(lambda: stopped(sim), 8, "Space to stop the robot")
        idle(0.6)  # the key is still down: the robot must stay still (lease ended, no resend)
        assert stopped(sim)
        gui.shot("stopped-with-up-held")
    finally:
        gui.keyup("Up")


def test_plus_and_minus_change_the_throttle_the_simulator_receives(gui: Gui, sim: SimThread) -> None:
    assert gui.operator.speed.value.percent == 50
    gui.key("plus")
    pump(lambda: gui.operator.speed.value.percent == 60, 3, "the speed to rise to 60 %")
    assert gui.window.banners.text("speed") == "Speed 60 %"
    gui.shot("speed-banner")
    gui.keydown("Up")
    try:
        pump(lambda: (received(sim) or (0, 0, 0, 0))[2] == 60, 5, "ratioDrive with throttle 60")
    finally:
        gui.keyup("Up")
    pump(lambda: stopped(sim), 8, "the robot to stop")
    gui.key("minus", "minus", "minus")
    pump(lambda: gui.operator.speed.value.percent == 30, 3, "the speed to drop to 30 %")
    gui.keydown("Up")
    try:
        pump(lambda: (received(sim) or (0, 0, 0, 0))[2] == 30, 5, "ratioDrive with throttle 30")
    finally:
        gui.keyup("Up")


# -- views --------------------------------------------------------------------------------------------


def test_escape_shows_the_camera_picture_and_escape_returns_to_the_map(gui: Gui) -> None:
    window = gui.window
    gui.key("Escape")
    pump(lambda: window.stack.get_visible_child_name() == "camera", 3, "the camera page")
    pump(lambda: window.camera.texture is not None, 8, "the picture to arrive and be decoded")
    assert "getPicture" in window.camera.info.get_text()
    gui.shot("camera")
    gui.key("Escape")
    pump(lambda: window.stack.get_visible_child_name() == "map", 3, "the map page")
    pump(lambda: window.inset.get_visible(), 3, "the picture inset on the map")
    gui.shot("map-with-inset")


def test_the_camera_inset_shows_its_age_greys_on_a_lost_link_and_clears_on_reconnect(
    gui: Gui, sim: SimThread
) -> None:
    window, inset, stage = gui.window, gui.window.inset, gui.stage
    gui.key("Escape")
    pump(lambda: window.camera.texture is not None, 8, "a picture")
    gui.key("Escape")
    pump(lambda: inset.get_visible() and inset.get_mapped(), 3, "the inset on the map")
    first = inset.age_label.get_text()
    assert re.fullmatch(r"(old picture · )?\d+ s", first), first  # whole seconds; old after INSET_OLD_AFTER
    pump(lambda: inset.age_label.get_text() != first, 3, "the age to count up")
    # Small (about a sixth of the map's width) and out of the way: the bottom-left corner.
    assert inset.get_width() <= 0.18 * stage.get_width(), (inset.get_width(), stage.get_width())
    ok, corner = inset.compute_bounds(stage)
    assert ok and corner.get_x() < 20 and corner.get_y() + corner.get_height() > stage.get_height() - 20
    gui.shot("inset-with-age")
    gui.click(inset)
    pump(lambda: window.stack.get_visible_child_name() == "camera", 3, "a click to open the camera page")
    gui.key("Escape")
    pump(lambda: window.stack.get_visible_child_name() == "map", 3, "the map again")
    port = sim.port
    sim.kill()
    pump(lambda: gui.phase is Phase.RECONNECTING, 5, "the lost link")
    pump(lambda: inset.age_label.get_text().endswith("link lost"), 3, "the inset to say the link is lost")
    assert inset.get_visible() and inset.has_css_class("stale")
    assert "before the link was lost" in (inset.get_tooltip_text() or "")
    gui.shot("inset-link-lost")
    with SimThread(SimConfig(port=port, map_path=OFFICE_MAP, camera=True, seed=1)):
        gui.wait_connected(timeout=20)
        assert not inset.get_visible() and inset.picture.get_paintable() is None, "an old picture is gone"
        gui.shot("reconnected-without-the-old-picture")


def test_ctrl_t_toggles_the_status_toolbar(gui: Gui) -> None:
    revealer = gui.window.toolbar_revealer
    assert revealer.get_reveal_child()
    gui.key("ctrl+t")
    pump(
        lambda: not revealer.get_reveal_child() and not revealer.get_child_revealed(),
        3,
        "the toolbar to hide",
    )
    gui.shot("toolbar-hidden")
    gui.key("ctrl+t")
    pump(lambda: revealer.get_reveal_child() and revealer.get_child_revealed(), 3, "the toolbar to show")
    gui.shot("toolbar-shown")


# -- connection life ----------------------------------------------------------------------------------


def test_disconnect_and_reconnect_without_restarting(gui: Gui, sim: SimThread) -> None:
    window = gui.window
    gui.key("ctrl+d")
    pump(lambda: gui.phase is Phase.DISCONNECTED, 3, "the disconnect")
    assert window.banners.text("link") is None, "a deliberate disconnect shows no banner"
    assert window.connect_button.get_label() == "Connect"
    assert window.toolbar.cells["x"].stale
    gui.shot("disconnected")
    gui.key("ctrl+o")
    gui.wait_connected()
    gui.shot("reconnected")
    start = sim.snapshot()
    gui.keydown("Up")
    try:
        pump(lambda: sim.snapshot().x > start.x + 100, 8, "driving after the reconnect")
    finally:
        gui.keyup("Up")
    pump(lambda: stopped(sim), 8, "the robot to stop")


def test_simulator_killed_while_driving(gui: Gui, sim: SimThread) -> None:
    """Lost link: one banner counting attempts, robot stopped, window alive; then only a new press drives."""
    window = gui.window
    port = sim.port
    gui.keydown("Up")
    try:
        pump(lambda: moving(sim), 8, "the robot to move")
        sim.kill()
        pump(lambda: gui.phase is Phase.RECONNECTING, 5, "the client to notice the lost link")
        pump(
            lambda: (window.banners.text("link") or "").startswith("Link lost — reconnecting"),
            3,
            "the banner",
        )
        assert window.controller.held == frozenset(), "held keys are dropped when the link goes"
        assert window.toolbar.cells["x"].stale and window.stage.robot_is_stale(), "old values look old"
        assert not window.controller.link.lease.view().live, "no drive lease survives the lost link"
        probe = LoopProbe()
        idle(1.0)
        probe.close()
        assert probe.beats >= 5, "the main loop keeps running"
        pump(lambda: gui.model.connection.value.attempt >= 2, 10, "a second reconnect attempt")
        texts = [window.banners.text(t) for t in window.banners.topics()]
        assert sum("Link lost" in (t or "") for t in texts) == 1, texts
        assert (
            window.banners.text("link") == f"Link lost — reconnecting ({gui.model.connection.value.attempt})…"
        )
        gui.shot("link-lost")
        # The robot comes back on the same port; the key is STILL held, yet nothing moves.
        with SimThread(SimConfig(port=port, map_path=OFFICE_MAP, seed=1)) as again:
            gui.wait_connected(timeout=20)
            idle(0.8)
            assert stopped(again), "a key held through a reconnect must not drive"
            # Lost while driving: the reconnect's first packets are a stop (zero ratios), never a drive.
            assert received(again) in (None, (0.0, 0.0, 0.0, 0.0)), received(again)
            gui.shot("reconnected-key-still-held")
            gui.keyup("Up")
            gui.keydown("Up")
            pump(lambda: moving(again), 8, "a fresh press to drive again")
            gui.keyup("Up")
            pump(lambda: stopped(again), 8, "the robot to stop")
    finally:
        gui.keyup("Up")


def header_close_button(gui: Gui):  # type: ignore[no-untyped-def]
    """The × of the header bar's window controls (what the operator clicks to close)."""
    from gi.repository import Gtk

    def walk(widget):  # type: ignore[no-untyped-def]
        yield widget
        child = widget.get_first_child()
        while child is not None:
            yield from walk(child)
            child = child.get_next_sibling()

    found = [
        w for w in walk(gui.window.get_titlebar()) if isinstance(w, Gtk.Button) and w.has_css_class("close")
    ]
    assert len(found) == 1, found
    return found[0]


@pytest.mark.parametrize("how", ["close-button", "ctrl-q"])
def test_closing_while_driving_sends_an_explicit_stop(gui: Gui, sim: SimThread, how: str) -> None:
    """Closing must stop the robot by itself, not leave it to the drive lease running out.

    The lease is made long (30 s) for this test, so if closing sent no stop the robot would
    keep driving (the client resends ratioDrive while the lease lives, so the simulator's own
    watchdog never fires either) and the wait for the stop would time out.
    """
    window = gui.window
    window.controller.link.lease.ttl = 30.0
    watchdog_stops = sim.call(lambda: sim.server.robot.watchdog_stops)
    gui.keydown("Up")
    try:
        pump(lambda: moving(sim), 8, "the robot to move")
        assert sim.call(lambda: sim.server.robot.mode_name) == "ratioDrive"
        gui.shot(f"driving-before-{how}")
        if how == "close-button":
            gui.click(header_close_button(gui))
        else:
            gui.key("ctrl+q")
        pump(lambda: not window.get_visible(), 3, "the window to close")
        pump(lambda: sim.call(lambda: sim.server.robot.mode_name) == "stop", 3, "an explicit stop")
        pump(lambda: stopped(sim), 8, "the robot to stop")
        assert sim.call(lambda: sim.server.robot.watchdog_stops) == watchdog_stops, (
            "stopped by us, not by ARIA"
        )
    finally:
        gui.keyup("Up")


def test_a_stalled_network_thread_is_reported_and_the_warning_goes_when_it_runs_again(gui: Gui) -> None:
    """``runner.loop_lag()`` above 0.5 s: the window says drive commands and stops are not going out."""
    window = gui.window
    runner = window.controller.link
    assert runner.loop_lag() is not None, "the real runner beats"
    idle(0.4)
    assert window.banners.text("loop") is None, "a running loop raises no warning"
    lag = [0.8]
    runner.loop_lag = lambda: lag[0]  # a stalled loop, as the runner would report it
    pump(lambda: window.banners.text("loop") is not None, 3, "the stall warning")
    text = window.banners.text("loop") or ""
    assert "0.8 s" in text and "watchdog" in text, text
    gui.shot("network-thread-stalled")
    lag[0] = 0.05
    pump(lambda: window.banners.text("loop") is None, 3, "the warning to go")
    gui.shot("network-thread-running-again")

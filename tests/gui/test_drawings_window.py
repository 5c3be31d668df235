"""The server's drawings in the real window: drawn in their colours, switched by real clicks.

Real window, real simulator, real X input. The simulator's sonar (light-blue arrows) and laser
(blue dots) are found in the stage's own pixels where their points are; switching the laser off
in the Layers panel (a real click) takes its pixels away, ends its request at the simulator and is
remembered for that server; switching it on brings both back. Against a hostile server: markup in
a name is shown literally, an unknown shape is listed greyed and never asked for, a lying point
count is named, and a flood of 3 998-point samples every 20 ms leaves the window answering keys.
"""

from __future__ import annotations

import time

import numpy as np

from client.drawing_servers import MARKUP, hostile_drawing_server
from client.servers import ServerThread
from rtmu.sim import SimThread
from rtmu.ui.options import GuiOptions
from simulators import simulator

from .harness import OFFICE_MAP, Gui, LoopProbe, idle, pump, scratch_dir
from .process import PATIENCE

LASER, SONAR = "sim_lms2xx_1Current", "sonarCurrent"
BLUE, SKY = (0, 0, 255), (0x33, 0xCC, 0xFF)


sim = simulator(map_path=OFFICE_MAP, camera=False, seed=1)


def layer(gui: Gui, name: str):  # type: ignore[no-untyped-def]
    return next((d for d in gui.model.drawings.value.layers if d.name == name), None)


def requested_at(sim: SimThread) -> set[str]:
    assert sim.server is not None
    server = sim.server
    return sim.call(lambda: {sub.name for s in server.sessions for sub in s.subscriptions.values()})


def count(pixels: np.ndarray, rgb: tuple[int, int, int]) -> int:
    return int(np.all(pixels == np.array(rgb, np.uint8), axis=-1).sum())


def share_on_colour(gui: Gui, pixels: np.ndarray, points, rgb) -> float:  # type: ignore[no-untyped-def]
    """Of the points inside the stage, the share whose own pixel has exactly the colour ``rgb``."""
    vp = gui.stage.viewport
    hits = total = 0
    for x, y in points:
        sx, sy = (round(v) for v in vp.to_screen(x, y))
        if 0 <= sx < pixels.shape[1] and 0 <= sy < pixels.shape[0]:
            total += 1
            hits += tuple(int(c) for c in pixels[sy, sx]) == rgb
    assert total > 0, "no point of the drawing is on screen"
    return hits / total


def test_sonar_and_laser_in_their_colours_and_a_layer_switched_off_is_gone_and_not_asked_for(
    gui: Gui, sim: SimThread
) -> None:
    pump(lambda: layer(gui, LASER) is not None and len(layer(gui, LASER).points) > 20, 10, "laser points")
    pump(lambda: layer(gui, SONAR) is not None and len(layer(gui, SONAR).points) > 0, 10, "sonar points")
    idle(0.3)
    pixels = gui.stage_pixels()
    gui.shot("drawn")
    # Points may move between the sample and the picture only if the robot moves: it stands still.
    assert share_on_colour(gui, pixels, layer(gui, LASER).points, BLUE) > 0.8
    assert count(pixels, SKY) > 10 and count(pixels, BLUE) > 50
    assert {LASER, SONAR} <= requested_at(sim)

    gui.window.activate_action("win.layers", None)
    panel = gui.window.layers
    pump(lambda: panel.get_mapped() and LASER in panel.buttons, 5, "the Layers panel")
    assert [panel.label_text(name) for name in panel.buttons] == [SONAR, LASER]  # by layer, as sent
    gui.screen_shot("layers-open")
    gui.click(panel.buttons[LASER])
    pump(lambda: not layer(gui, LASER).shown and layer(gui, LASER).points == (), 5, "the laser hidden")
    deadline = time.monotonic() + 5 * PATIENCE
    while LASER in requested_at(sim):
        assert time.monotonic() < deadline, "the simulator is still asked for the laser"
        idle(0.05)
    idle(0.3)
    pixels = gui.stage_pixels()
    gui.shot("laser-off")
    assert count(pixels, BLUE) == 0 and count(pixels, SKY) > 10
    assert SONAR in requested_at(sim)
    assert panel.choices[f"127.0.0.1:{sim.port}"] == {LASER: False}  # remembered for this server
    assert gui.window.is_active() and gui.window.get_focus() is None  # the panel took no keyboard

    gui.click(panel.buttons[LASER])
    pump(lambda: layer(gui, LASER).shown and len(layer(gui, LASER).points) > 20, 5, "the laser back")
    pump(lambda: LASER in requested_at(sim), 5, "the laser asked for again")
    idle(0.3)
    assert count(gui.stage_pixels(), BLUE) > 50
    gui.shot("laser-on")
    gui.focus()
    gui.key("Escape")  # closes the panel, and only the panel: the map stays (issue 21)
    pump(lambda: not panel.get_visible(), 3, "Escape to close the Layers panel")
    assert not gui.window.camera_page.showing, "Escape went to the camera page instead"


def test_a_hostile_servers_drawings_leave_the_window_answering(screenshots) -> None:  # type: ignore[no-untyped-def]
    with ServerThread(hostile_drawing_server()) as server:
        gui = Gui.start(screenshots, "hostile-drawings", "127.0.0.1", server.port)
        try:
            pump(
                lambda: layer(gui, "max") is not None and len(layer(gui, "max").points) > 3000,
                10,
                "the flood",
            )
            pump(
                lambda: layer(gui, "huge") is not None and layer(gui, "huge").problem != "",
                10,
                "the lie named",
            )
            gui.window.activate_action("win.layers", None)
            panel = gui.window.layers
            pump(lambda: panel.get_mapped() and MARKUP in panel.buttons, 5, "the Layers panel")
            assert panel.label_text(MARKUP) == MARKUP  # literally: no bold, no mnemonic underscore
            assert not panel.buttons[MARKUP].get_child().get_use_markup()
            assert not panel.buttons["blob"].get_sensitive()
            assert panel.label_text("blob") == "blob — shape 'polyHexagons' not drawn"
            assert panel.label_text("huge") == "huge — bad data"
            assert "blob" not in server.names()
            gui.screen_shot("hostile-layers")
            # The window keeps answering while 3 998-point samples arrive every 20 ms.
            frames, probe = gui.stage.frames, LoopProbe()
            before = gui.operator.speed.value.percent
            gui.focus()
            gui.key("plus")
            pump(lambda: gui.operator.speed.value.percent == before + 10, 5, "the speed key")
            # New samples (each one moved) keep being drawn (waited for: a busy machine may take longer
            # than a second).
            pump(lambda: gui.stage.frames > frames, 5, "a frame drawn during the flood")
            idle(1.0)
            probe.close()
            assert probe.beats > 3
            # Drawings without status still get frames of their own (waited for: on a busy machine the
            # frames the key and the panel asked for may show the drawings first for a while).
            pump(lambda: gui.stage.drawings_redraws > 0, 10, "a frame asked for by the drawings alone")
            assert gui.model.connection.value.connected
            gui.shot("hostile-flood")
        finally:
            gui.close()


def test_a_layer_switched_off_stays_off_for_that_server_after_a_restart(screenshots, sim: SimThread) -> None:  # type: ignore[no-untyped-def]
    settings = scratch_dir("settings-") / "settings.toml"
    options = GuiOptions(host="127.0.0.1", port=sim.port, settings_path=settings, persist=True)
    gui = Gui.open(options, screenshots, "layers-remembered-1")
    try:
        pump(lambda: layer(gui, LASER) is not None and layer(gui, LASER).points, 10, "laser points")
        gui.window.activate_action("win.layers", None)
        panel = gui.window.layers
        pump(lambda: panel.get_mapped() and LASER in panel.buttons, 5, "the Layers panel")
        gui.click(panel.buttons[LASER])
        pump(lambda: not layer(gui, LASER).shown, 5, "the laser hidden")
        gui.shot("switched-off")
    finally:
        gui.close()
    text = settings.read_text()
    assert f'[layers."127.0.0.1:{sim.port}"]' in text and f'"{LASER}" = false' in text
    gui = Gui.open(options, screenshots, "layers-remembered-2")
    try:
        pump(lambda: layer(gui, SONAR) is not None and layer(gui, SONAR).points, 10, "sonar points")
        assert not layer(gui, LASER).shown and layer(gui, LASER).points == ()
        assert LASER not in requested_at(sim) and SONAR in requested_at(sim)
        idle(0.3)
        assert count(gui.stage_pixels(), BLUE) == 0
        gui.shot("still-off")
    finally:
        gui.close()


def test_drawings_ride_on_the_status_frames_instead_of_redrawing_the_map_each_update(
    gui: Gui, sim: SimThread
) -> None:
    """Each drawings update once asked for a map frame of its own, on top of the robot's status
    frames: with live video that doubled the map's repaints and tripled the window's frame time.
    While status comes, new drawings are shown by the next status frame and ask for none."""
    pump(lambda: layer(gui, LASER) is not None and len(layer(gui, LASER).points) > 20, 10, "laser points")
    assert sim.server is not None
    world = sim.server.world
    updates = [0]
    # Status frames come every 100 ms; the drawings' own wait is made longer than a busy machine's stall
    # (150 ms is the product's), so a frame asked for by drawings here means they did not wait for one.
    gui.stage.drawings_wait_ms = 1000
    remove = gui.model.drawings.observe(lambda _old, _new: updates.__setitem__(0, updates[0] + 1))
    try:
        asked, frames = gui.stage.drawings_redraws, gui.stage.frames
        for _ in range(5):  # the robot turns on the spot: every laser sample is new
            sim.call(lambda: world.ratio_drive(0, 25, 100))
            idle(0.4)
    finally:
        remove()
    assert updates[0] >= 5, "the simulator's drawings did not keep coming"
    assert gui.stage.frames - frames >= 5, "the map was not redrawn by the robot's status"
    assert gui.stage.drawings_redraws - asked <= 1  # a status frame may come late once
    sim.call(lambda: world.ratio_drive(0, 0, 100))
    idle(0.5)
    assert count(gui.stage_pixels(), BLUE) > 50  # and the laser is still drawn
    gui.shot("drawings-with-status")

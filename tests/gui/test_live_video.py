"""Live video in the real window: it plays (frames differ, figures shown), pauses, saves a frame; the
picture-in-picture is moved, resized and hidden with real pointer drags; the split view; the wedge."""

from __future__ import annotations

import re
import time
from pathlib import Path

import gi
import numpy as np
from PIL import Image

from rtmu.sim import SimThread
from simulators import simulator

from .harness import OFFICE_MAP, Gui, idle, pump

gi.require_version("Gdk", "4.0")
from gi.repository import Gdk, GLib  # noqa: E402

sim = simulator(map_path=OFFICE_MAP, camera=True, seed=1, camera_hz=20.0, drive_timeout=0)
"""A camera serving up to 20 new frames/s on a robot turning on the spot, so every frame is new."""


def turn(sim: SimThread) -> None:
    """Turn the robot on the spot (after the window connected: a new connection stops the robot)."""
    assert sim.server is not None
    world = sim.server.world
    sim.call(lambda: world.ratio_drive(0, 30, 100))


def picture_pixels(gui: Gui, label: str) -> np.ndarray:
    path = gui.render(gui.window.camera.picture, gui.shots / f"{gui.name}-{label}.png")
    with Image.open(path) as img:
        return np.asarray(img.convert("RGB")).astype(int)


def start_live(gui: Gui, sim: SimThread) -> None:
    window = gui.window
    gui.key("Escape")
    pump(lambda: window.stack.get_visible_child_name() == "camera", 3, "the camera page")
    gui.click(window.live.live_button)
    pump(lambda: window.live.live, 3, "Live to be on")
    idle(0.3)  # the window stops the robot around key presses; turn it once the keys are done
    turn(sim)


def frames_seen(gui: Gui) -> int:
    image = gui.window.camera.image
    return 0 if image is None else image.sequence


def test_live_video_plays_pauses_and_saves_a_frame(gui: Gui, sim: SimThread, tmp_path: Path) -> None:
    window, live = gui.window, gui.window.live
    live.folder = tmp_path
    start_live(gui, sim)
    pump(lambda: window.camera.image is not None and window.camera.image.video is not None, 8, "a live frame")
    first = frames_seen(gui)
    pump(lambda: frames_seen(gui) >= first + 5, 8, "five more frames")
    # The figures are on the picture: frames per second, kB/s and the frame's age (the simulator stamps it).
    pump(lambda: re.search(r"\d+\.\d fps · \d+ kB/s · \d+ ms old", live.caption.get_text()), 3, "the figures")
    assert live.caption.get_visible()
    # One age on screen, the caption's: the bar's line says none while it plays (issue 21).
    pump(lambda: " old" not in window.camera.info.get_text(), 3, "the bar's age to give way")
    # Back to the map and to the camera again: live video is the picture, nothing is "requested" over it.
    requests: list[float] = []
    asked = window.camera.requesting
    window.camera.requesting = lambda: (requests.append(time.monotonic()), asked())[1]  # type: ignore[method-assign]
    gui.key("Escape")
    pump(lambda: not window.camera_page.showing, 3, "the map")
    gui.key("Escape")
    pump(lambda: window.camera_page.showing, 3, "the camera page")
    assert requests == [], "a single picture (and its spinner) was asked for over live video"
    assert not window.camera.status_box.get_visible(), "a spinner over video"
    del window.camera.requesting
    a = picture_pixels(gui, "01-playing")
    pump(lambda: frames_seen(gui) >= first + 10, 8, "more frames")
    b = picture_pixels(gui, "02-playing-later")
    changed = float((np.abs(a - b).sum(axis=2) > 24).mean())
    assert changed > 0.005, f"consecutive screenshots of turning video differ ({changed:.4f} changed)"
    gui.shot("live")

    gui.click(live.pause_button)
    pump(lambda: live.pause_button.get_active(), 3, "Pause")
    idle(0.5)  # a frame already asked for may still arrive
    paused_at = frames_seen(gui)
    idle(1.0)
    assert frames_seen(gui) == paused_at, "no frames while paused"
    pump(lambda: " old" in window.camera.info.get_text(), 3, "the bar's age back while paused")
    gui.shot("paused")
    gui.click(live.pause_button)
    pump(lambda: frames_seen(gui) > paused_at, 5, "frames again after Pause is released")

    gui.click(live.save_button)
    pump(lambda: bool(live.saved), 3, "the frame to be saved")
    saved = live.saved[-1]
    assert saved.parent == tmp_path and saved.read_bytes()[:2] == b"\xff\xd8"
    with Image.open(saved) as img:
        assert img.size == (320, 240)
    assert str(saved) in (window.banners.text("camera") or "")

    gui.click(live.live_button)
    pump(lambda: not live.live, 3, "Live off")
    idle(0.5)
    stopped_at = frames_seen(gui)
    idle(1.0)
    assert frames_seen(gui) == stopped_at, "Live off stops the requests"


def inset_bounds(gui: Gui) -> tuple[float, float, float, float]:
    inset = gui.window.inset
    ok, rect = inset.compute_bounds(gui.stage)
    assert ok
    return rect.get_x(), rect.get_y(), rect.get_width(), rect.get_height()


def drag(gui: Gui, widget, dx: int, dy: int) -> None:  # type: ignore[no-untyped-def]
    """A real pointer drag through the X server from the middle of ``widget`` by (dx, dy), in steps."""
    x, y = gui.centre_on_surface(widget)
    xid = str(gui.xid())
    # The pointer rests on the widget before the press (as in the PTZ drag): pressed in the same xdotool
    # call as the move, a busy window could take the press before it had seen the pointer arrive.
    gui.xdotool("mousemove", "--window", xid, str(x), str(y))
    idle(0.3)
    args = ["mousedown", "1"]
    for i in range(1, 9):
        args += ["sleep", "0.03", "mousemove", "--window", xid, str(x + dx * i // 8), str(y + dy * i // 8)]
    args += ["sleep", "0.05", "mouseup", "1"]
    gui.xdotool(*args)
    idle(0.2)


def test_the_picture_in_picture_moves_resizes_and_hides(gui: Gui, sim: SimThread) -> None:
    window, inset = gui.window, gui.window.inset
    start_live(gui, sim)
    pump(lambda: window.camera.image is not None and window.camera.image.video is not None, 8, "a live frame")
    gui.key("Escape")
    pump(lambda: inset.get_visible() and inset.get_mapped(), 3, "the picture over the map")
    x0, y0, w0, h0 = inset_bounds(gui)
    first = frames_seen(gui)
    pump(lambda: frames_seen(gui) >= first + 3, 8, "the picture to stay live on the map")
    gui.shot("pip-start")

    drag(gui, inset.picture, 220, -150)
    pump(lambda: abs(inset_bounds(gui)[0] - (x0 + 220)) < 12, 3, "the picture to move right")
    x1, y1, w1, h1 = inset_bounds(gui)
    assert abs(y1 - (y0 - 150)) < 12 and abs(w1 - w0) < 1 and abs(h1 - h0) < 1
    assert window.stack.get_visible_child_name() == "map", "a drag is not a click"
    gui.shot("pip-moved")

    drag(gui, inset.grip, 120, 90)
    pump(lambda: inset_bounds(gui)[2] > w0 + 80, 3, "the picture to grow")
    x2, y2, w2, h2 = inset_bounds(gui)
    assert abs(x2 - x1) < 3 and abs(y2 - y1) < 3, "resizing keeps the corner where it was"
    assert abs(w2 / h2 - w0 / h0) < 0.1
    gui.shot("pip-resized")

    gui.click(inset.close_button)
    pump(lambda: not inset.get_visible(), 3, "the picture to hide")
    assert window.inset_action.get_state().get_boolean() is False
    gui.shot("pip-hidden")
    window.activate_action("win.inset", None)
    pump(lambda: inset.get_visible(), 3, "the picture back from the View menu")
    assert abs(inset_bounds(gui)[0] - x2) < 3, "it comes back where it was put"


def test_split_view_shows_map_and_live_video_side_by_side(gui: Gui, sim: SimThread) -> None:
    window, split = gui.window, gui.window.split
    turn(sim)
    window.activate_action("win.split", None)  # View ▸ Split view: map and video
    pump(lambda: split.pane.get_mapped(), 3, "the video pane")
    pump(lambda: window.live.live, 3, "the split view to start live video")
    pump(lambda: split.picture.get_paintable() is not None, 8, "a frame in the pane")
    pump(lambda: "fps" in split.caption.get_text(), 5, "the figures in the pane")
    assert window.stack.get_visible_child_name() == "map"
    ok, pane = split.pane.compute_bounds(split)
    ok2, stage = gui.stage.compute_bounds(split)
    assert ok and ok2
    assert pane.get_x() >= stage.get_x() + stage.get_width() - 2, "the video is beside the map"
    assert abs(pane.get_width() - stage.get_width()) < 0.1 * split.get_width()
    assert not window.inset.get_visible(), "the map's inset repeats the picture shown beside it"
    gui.shot("split")
    window.activate_action("win.split", None)
    pump(lambda: not split.pane.get_visible(), 3, "the pane to close")
    pump(lambda: window.inset.get_visible(), 3, "the map's inset back without the pane")
    gui.shot("split-off")


def amber_pixels(pixels: np.ndarray) -> int:
    r, g, b = pixels[..., 0].astype(int), pixels[..., 1].astype(int), pixels[..., 2].astype(int)
    return int(np.count_nonzero((r - b > 60) & (r > 150) & (g > 90) & (g < r)))


def test_the_field_of_view_wedge_is_drawn_and_can_be_switched_off(gui: Gui) -> None:
    window = gui.window
    with_wedge = gui.stage_pixels()
    window.activate_action("win.fov", None)
    pump(lambda: not gui.stage.show_fov, 3, "the wedge off")
    idle(0.3)
    without = gui.stage_pixels()
    assert amber_pixels(with_wedge) > amber_pixels(without) + 200, "the amber wedge is on the map"
    gui.shot("no-wedge")


def test_the_v_key_plays_live_video_over_the_map_and_stops_it(gui: Gui, sim: SimThread) -> None:
    """V (a letter no drive uses) toggles Live from the map page: the picture over the map plays."""
    from rtmu.ui.keys import KeyRouter, bindings
    from rtmu.ui.keys_sheet import KeySheet

    window, live = gui.window, gui.window.live
    assert [b.action for b in bindings() if "v" in b.accels] == ["win.live-video"], "V is for video only"
    assert "Live video on/off" in [r.title for r in KeySheet.of(bindings()).rows]
    router = KeyRouter(hold=print, release=print, activate=print)
    for key in ("v", "V"):
        keyval = Gdk.keyval_from_name(key)
        found = router.lookup(keyval, Gdk.ModifierType.SHIFT_MASK if key == "V" else Gdk.ModifierType(0))
        assert found is not None and found.action == "win.live-video", key

    gui.key("v")
    pump(lambda: live.live, 3, "V to start live video")
    assert window.stack.get_visible_child_name() == "map", "V plays where the operator is"
    idle(0.3)
    turn(sim)
    pump(lambda: window.inset.get_visible() and frames_seen(gui) > 0, 8, "the live picture over the map")
    first = frames_seen(gui)
    pump(lambda: frames_seen(gui) >= first + 5, 8, "five more frames")
    gui.shot("v-live-over-map")
    gui.key("v")
    pump(lambda: not live.live, 3, "V again to stop")
    idle(0.5)
    stopped_at = frames_seen(gui)
    idle(1.0)
    assert frames_seen(gui) == stopped_at, "V off stops the requests"


def test_frames_keep_coming_whether_or_not_a_picture_is_on_screen(gui: Gui, sim: SimThread) -> None:
    """The next frame is asked for after the paint that shows this one, and at once when no picture is
    on screen (the map page with the picture-in-picture hidden): either way the video keeps its rate.
    The robot stands still while the simulator's camera head sweeps, so every frame is new. (The
    window's link figures repaint it several times a second anyway, so this cannot tell the at-once
    path from a wait for the next paint; it holds the rate with and without a picture on screen.)"""
    window, inset = gui.window, gui.window.inset
    assert sim.server is not None
    head = sim.server.world.camera.ptz

    def sweep() -> bool:
        sim.call(lambda: setattr(head, "pan", (head.pan + 3.0) % 90.0))
        return True

    gui.key("v")
    pump(lambda: window.live.live, 3, "V to start live video")
    source = GLib.timeout_add(40, sweep)
    try:
        pump(lambda: inset.get_mapped() and frames_seen(gui) > 0, 8, "the picture over the map")
        first = frames_seen(gui)
        idle(2.0)
        shown = frames_seen(gui) - first
        gui.click(inset.close_button)
        pump(lambda: not inset.get_visible(), 3, "the picture to hide")
        assert not window.camera.get_mapped() and not window.split.pane.get_mapped()
        idle(0.5)
        first = frames_seen(gui)
        idle(2.0)
        hidden = frames_seen(gui) - first
    finally:
        GLib.source_remove(source)
    gui.shot("no-picture-on-screen")
    assert shown >= 6 and hidden >= 6, f"{shown} frames in 2 s on screen, {hidden} with none on screen"

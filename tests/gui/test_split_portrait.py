"""The split view on a 360×720 portrait phone (an X server whose only screen has that size, no window
manager): map and live video stacked, the map above, each about half the height, both drawn inside the
screen — the map's pixels and the video's, which change as the simulated robot turns."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import gi
import numpy as np
import pytest
from PIL import Image

from rtmu.sim import SimThread
from simulators import running

from .harness import OFFICE_MAP, Gui, idle, on_display, pump, scratch_dir

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

W, H = 360, 720


@pytest.fixture
def phone(
    screenshots: Path, phone_screen: str, request: pytest.FixtureRequest
) -> Iterator[tuple[Gui, SimThread]]:
    with (
        running(map_path=OFFICE_MAP, camera=True, seed=1, camera_hz=20.0, drive_timeout=0) as sim,
        on_display(phone_screen),
    ):
        gui = Gui.start(screenshots, request.node.name, "127.0.0.1", sim.port)
        try:
            yield gui, sim
        finally:
            gui.close()


def bounds(widget: Gtk.Widget, window: Gtk.Window) -> tuple[float, float, float, float]:
    """The widget's box on the window's X surface (the surface's own shadow margin added)."""
    ok, rect = widget.compute_bounds(window)
    assert ok
    dx, dy = window.get_surface_transform()
    return rect.get_x() + dx, rect.get_y() + dy, rect.get_width(), rect.get_height()


def pixels(gui: Gui, widget: Gtk.Widget, label: str) -> np.ndarray:
    path = gui.render(widget, scratch_dir("split-") / f"{label}.png")
    with Image.open(path) as img:
        return np.asarray(img.convert("RGB")).astype(int)


def test_split_view_stacks_map_over_live_video_on_a_portrait_phone(phone: tuple[Gui, SimThread]) -> None:
    gui, sim = phone
    window, split = gui.window, gui.window.split
    pump(lambda: window.handheld.layout.narrow, 5, "the phone layout")
    idle(0.3)
    assert gui.screen_rect(window) == (0, 0, W, H), gui.screen_rect(window)
    pump(lambda: gui.model.map.value.state == "ready", 10, "the map")
    window.activate_action("win.split", None)  # View ▸ Split view
    pump(lambda: split.pane.get_mapped() and window.live.live, 3, "the video pane, playing")
    idle(0.3)
    assert sim.server is not None
    world = sim.server.world
    sim.call(lambda: world.ratio_drive(0, 30, 100))  # turn on the spot: every frame is new
    pump(lambda: split.picture.get_paintable() is not None, 8, "a frame in the pane")
    pump(lambda: split.get_orientation() == Gtk.Orientation.VERTICAL, 3, "the split to stack")
    pump(lambda: "fps" in split.caption.get_text(), 5, "the figures in the pane")
    idle(0.3)

    sx, sy, sw, sh = bounds(gui.stage, window)
    px, py, pw, ph = bounds(split.pane, window)
    assert py >= sy + sh - 2, f"the video is under the map: map {sx, sy, sw, sh}, video {px, py, pw, ph}"
    assert abs(pw - sw) < 0.1 * W and pw > 0.8 * W, "both take the phone's width"
    assert sh > 0.25 * H and ph > 0.25 * H, "each gets a good share of the height"
    assert px >= -0.5 and py + ph <= H + 0.5, "the video pane is inside the screen"
    gui.shot("split-portrait")

    map_px = pixels(gui, gui.stage, "map")
    assert (map_px.sum(axis=2) < 300).sum() > 200, "the map's walls are drawn in the upper half"
    a = pixels(gui, split.picture, "video-a")
    first = split.picture.get_paintable()
    pump(lambda: split.picture.get_paintable() is not first, 5, "a newer frame")
    idle(0.3)
    b = pixels(gui, split.picture, "video-b")
    assert a.std() > 10, "the pane shows a picture, not a blank"
    assert float((np.abs(a - b).sum(axis=2) > 24).mean()) > 0.005, "the video plays in the lower half"

    window.activate_action("win.split", None)
    pump(lambda: not split.pane.get_visible(), 3, "the pane to close")
    idle(0.3)
    _x, _y, _w, sh2 = bounds(gui.stage, window)
    assert sh2 > sh * 1.5, "the map takes the whole height again"
    gui.shot("split-portrait-off")

"""Fit leaves the zoom buttons and the D-pad room (issue 21, "D-pad" and the zoom row).

Before, Fit kept the map clear of the D-pad only: the zoom row (bottom right) still covered a
corner of the map at 800×480 and 360×720. Now Fit fits the map in what the zoom row and the D-pad
leave. On a screen of each size (the window fills it; 1280×800 on the session's screen), with the
D-pad shown (picked from the menu with the mouse; a phone shows it by itself), Ctrl+0 fits, and the
map's drawn extent is clear of the zoom row and of the D-pad, in split view too (a 395 px map: the
D-pad's pads are compact there, so the map fits above them at a legible size, where the 64 px pads
left it so little room that Fit gave up and the D-pad lay over the robot). Space and STOP stop the
robot there.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import gi
import pytest

from rtmu.sim import SimConfig, SimThread

from .harness import OFFICE_MAP, Gui, on_display, pump
from .test_dpad_place import Rect, overlap, pick, rect, settled
from .test_phone_wm import space_and_stop_stop

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402


@pytest.fixture
def sim() -> Iterator[SimThread]:
    with SimThread(SimConfig(port=0, map_path=OFFICE_MAP, camera=True, seed=1)) as s:
        yield s


def map_extent(gui: Gui) -> Rect:
    """The map's walls and points as drawn now, in the map page's terms."""
    stage = gui.stage
    bounds = stage.tiles.bounds
    assert bounds is not None
    x0, y0, x1, y1 = bounds
    corners = [stage.viewport.to_screen(x, y) for x in (x0, x1) for y in (y0, y1)]
    ok, origin = stage.compute_bounds(gui.window.map_page)
    assert ok
    dx, dy = origin.get_x(), origin.get_y()
    xs, ys = [c[0] + dx for c in corners], [c[1] + dy for c in corners]
    return min(xs), min(ys), max(xs), max(ys)


def fit(gui: Gui, label: str, *, dpad_clear: bool = True) -> None:
    """Ctrl+0, then the map's drawn extent clear of the zoom row and of the D-pad where shown."""
    window, page = gui.window, gui.window.map_page
    gui.focus()
    gui.key("ctrl+0")  # Fit
    pump(lambda: gui.stage.fitted, 5, "Fit")
    settled(gui)
    gui.screen_shot(f"fit-{label}")
    drawn, osd = map_extent(gui), rect(page.osd, page)
    assert not overlap(drawn, osd), f"{label}: at Fit the zoom row {osd} covers the map {drawn}"
    if dpad_clear and window.dpad.get_mapped():
        pad = rect(window.dpad, page)
        assert not overlap(drawn, pad), f"{label}: at Fit the D-pad {pad} covers the map {drawn}"


def fit_and_check(gui: Gui, sim: SimThread, label: str) -> None:
    window = gui.window
    if not window.dpad.get_visible():
        fit(gui, f"{label}-no-dpad")
        pick(gui, "win.dpad")  # View ▸ Touch D-pad, clicked
    pump(lambda: window.dpad.get_mapped(), 5, "the D-pad")
    fit(gui, label)
    if not window.handheld.layout.narrow:
        pick(gui, "win.split")  # split view: a narrower map beside the video
        pump(lambda: window.split.split and window.split.pane.get_mapped(), 5, "split view")
        fit(gui, f"{label}-split")  # a narrow map: compact pads, the map above them
        pick(gui, "win.split")
        pump(lambda: not window.split.split, 5, "split view to end")
    space_and_stop_stop(gui, sim, window.stop_button, f"at Fit, {label}")


def test_fit_leaves_the_zoom_row_and_dpad_room_at_800x480(
    screenshots: Path, small_screen: str, sim: SimThread
) -> None:
    with on_display(small_screen):
        gui = Gui.start(screenshots, "fit-room-800x480", "127.0.0.1", sim.port)
        try:
            fit_and_check(gui, sim, "800x480")
        finally:
            gui.close()


def test_fit_leaves_the_zoom_row_and_dpad_room_at_1280x800(gui: Gui, sim: SimThread) -> None:
    gui.window.set_default_size(1280, 800)
    pump(lambda: gui.window.get_width() >= 1200, 5, "the window at 1280 px")
    fit_and_check(gui, sim, "1280x800")


def test_fit_leaves_the_zoom_row_and_dpad_room_on_a_phone(
    screenshots: Path, phone_screen: str, sim: SimThread
) -> None:
    with on_display(phone_screen):
        gui = Gui.start(screenshots, "fit-room-360x720", "127.0.0.1", sim.port)
        try:
            pump(lambda: gui.window.handheld.layout.narrow, 5, "the phone layout")
            assert gui.window.dpad.get_halign() == Gtk.Align.CENTER
            fit_and_check(gui, sim, "360x720")
        finally:
            gui.close()

"""The D-pad where a thumb is, never over the robot or the other overlays (issue 21, "D-pad").

Before, at 800×480 "Fit" the D-pad covered the robot standing at Home; in split view it sat over the
zoom row of the narrow map; it was missing on the camera page; the Go-to-point bar lay over it. On
an 800×480 screen, with real input (the menu clicked, Ctrl+0, Escape, the Go to list clicked, the
D-pad held with the mouse): the robot at Fit is clear of the D-pad, the D-pad is in the bottom-left
corner clear of the zoom row (also in split view), the pick bar is clear of it, and on the camera
page it is there and drives — with Space stopping a navigation and a held D-pad drive each time.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import gi
import pytest

from rtmu.sim import SimThread
from simulators import running

from .harness import OFFICE_MAP, Gui, idle, on_display, pump
from .stop_paths import MenuPicker, StopCycle, menu_entries

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

Rect = tuple[float, float, float, float]


@pytest.fixture
def small(screenshots: Path, small_screen: str) -> Iterator[tuple[Gui, SimThread]]:
    with (
        running(map_path=OFFICE_MAP, camera=True, seed=1) as sim,
        on_display(small_screen),
    ):
        gui = Gui.start(screenshots, "dpad-place", "127.0.0.1", sim.port)
        try:
            yield gui, sim
        finally:
            gui.close()


def rect(widget: Gtk.Widget, ancestor: Gtk.Widget) -> Rect:
    ok, bounds = widget.compute_bounds(ancestor)
    assert ok, f"{widget} is not inside {ancestor}"
    x, y = bounds.get_x(), bounds.get_y()
    return x, y, x + bounds.get_width(), y + bounds.get_height()


def overlap(a: Rect, b: Rect) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def pick(gui: Gui, action: str) -> None:
    entry = next(e for e in menu_entries(gui.window.menu_model) if e.action == action)
    MenuPicker(gui).by_mouse(entry)


def settled(gui: Gui) -> None:
    idle(0.4)  # the placement runs in an idle after the layout; then a frame
    pump(lambda: gui.stage.last_frame_complete, 5, "a frame drawn")


def assert_in_corner_clear_of_the_zoom_row(gui: Gui) -> None:
    page = gui.window.map_page
    pad, osd = rect(gui.window.dpad, page), rect(page.osd, page)
    assert pad[0] < 40 and page.get_height() - pad[3] < 90, (
        f"the D-pad at {pad} is not in the bottom-left corner"
    )
    assert not overlap(pad, osd), f"the D-pad {pad} lies over the zoom row {osd}"


def test_the_dpad_keeps_to_its_corner_clear_of_the_robot_and_the_rest(small: tuple[Gui, SimThread]) -> None:
    gui, sim = small
    window = gui.window
    pick(gui, "win.dpad")  # View ▸ Touch D-pad, clicked
    pump(lambda: window.dpad.get_mapped(), 5, "the D-pad")
    gui.focus()
    gui.key("ctrl+0")  # Fit
    pump(lambda: gui.stage.fitted, 5, "Fit")
    settled(gui)
    gui.screen_shot("fit-800x480")
    robot = window.model.robot.value
    sx, sy = gui.stage.viewport.to_screen(robot.x, robot.y)
    pad = rect(window.dpad, gui.stage)
    body = (sx - 12, sy - 12, sx + 12, sy + 12)  # the robot as drawn at this zoom, and a margin
    assert not overlap(pad, body), f"at Fit the D-pad {pad} covers the robot at {(sx, sy)}"
    assert_in_corner_clear_of_the_zoom_row(gui)

    # Go to point: its bar keeps clear of the D-pad.
    gui.click(window.goals_panel)
    popover = window.goals_panel.get_popover()
    pump(lambda: popover is not None and popover.get_mapped(), 5, "the Go to list")
    gui.click(window.goals_panel.buttons["goto"])
    pump(lambda: window.map_page.pose_bar.get_mapped(), 5, "the Go-to-point bar")
    settled(gui)
    gui.screen_shot("go-to-point")
    page = window.map_page
    assert not overlap(rect(window.dpad, page), rect(page.pose_bar, page)), "the pick bar lies over the D-pad"
    gui.key("Escape")
    pump(lambda: not window.picker.active, 5, "the pick mode to end")

    # Split view: the narrow map lifts the D-pad above the zoom row, still in its corner.
    pick(gui, "win.split")
    pump(lambda: window.split.split and window.split.pane.get_mapped(), 5, "split view")
    settled(gui)
    gui.screen_shot("split-view")
    assert_in_corner_clear_of_the_zoom_row(gui)
    StopCycle(gui, sim).prove("split view with the D-pad")
    pick(gui, "win.split")
    pump(lambda: not window.split.split, 5, "split view to end")

    # The camera page has the D-pad too, and it drives there (and Space stops it).
    gui.focus()
    gui.key("Escape")
    pump(lambda: window.stack.get_visible_child_name() == "camera", 5, "the camera page")
    settled(gui)
    pump(lambda: window.dpad.get_mapped(), 5, "the D-pad on the camera page")
    pad = rect(window.dpad, window.camera.overlay)
    assert pad[0] < 40, f"the D-pad at {pad} is not in the camera page's left corner"
    gui.screen_shot("camera-page")
    cycle = StopCycle(gui, sim)
    cycle.hold_dpad()
    try:
        pump(cycle.driven, 8, "the D-pad on the camera page to drive")
        cycle.space_stops("during a held D-pad drive on the camera page")
        pump(lambda: not cycle.driven(), 5, "the held drive to end on Space")
    finally:
        gui.xdotool("mouseup", "1")
    cycle.navigate()  # the header's STOP, clicked on the camera page
    before = cycle.stops()
    gui.click(window.stop_button)
    pump(lambda: cycle.stops() > before, 5, "STOP on the camera page to stop the robot")
    gui.focus()
    gui.key("Escape")
    pump(lambda: window.stack.get_visible_child_name() == "map", 5, "the map page")
    settled(gui)
    pump(
        lambda: window.dpad.get_mapped() and window.dpad.get_parent() is window.map_page, 5, "the D-pad back"
    )

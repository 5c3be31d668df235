"""Full screen keeps Go to and the camera within reach (issue 21, "Layouts").

GTK hides the title bar in full screen, and with it the Go to, Routes and camera buttons; the
full-screen bar now carries them while it shows and gives them back after. In-process on a display
of its own with openbox (full screen needs a window manager): F11, then each button is clicked with
the mouse and does its job, Space and the bar's STOP stop a navigation in that state, and F11 puts them back.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import gi
import pytest

from rtmu.sim import SimThread
from simulators import running

from .harness import OFFICE_MAP, Gui, on_display, pump
from .stop_paths import StopCycle
from .test_fullscreen_wm import wm_display  # noqa: F401  (a fixture)

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402


@pytest.fixture
def wm_gui(screenshots: Path, wm_display: dict[str, str]) -> Iterator[tuple[Gui, SimThread]]:  # noqa: F811
    with (
        running(map_path=OFFICE_MAP, camera=True, seed=1) as sim,
        on_display(wm_display["DISPLAY"]),
    ):
        gui = Gui.start(screenshots, "fullscreen-buttons", "127.0.0.1", sim.port)
        try:
            yield gui, sim
        finally:
            gui.close()


def inside(widget: Gtk.Widget, ancestor: Gtk.Widget) -> bool:
    parent = widget.get_parent()
    while parent is not None and parent is not ancestor:
        parent = parent.get_parent()
    return parent is ancestor


def test_full_screen_keeps_go_to_and_the_camera_reachable(wm_gui: tuple[Gui, SimThread]) -> None:
    gui, sim = wm_gui
    window = gui.window
    bar, header = window.fullscreen_bar, window.header
    goto, camera = window.goals_panel, window.camera_button
    gui.key("F11")
    pump(lambda: window.is_fullscreen() and bar.get_child_revealed(), 10, "full screen and its bar")
    pump(lambda: goto.get_mapped() and camera.get_mapped(), 5, "Go to and the camera button on screen")
    assert inside(goto, bar) and inside(camera, bar), "the buttons are in the full-screen bar"
    gui.screen_shot("full-screen")
    gui.click(goto)
    popover = goto.get_popover()
    pump(lambda: popover is not None and popover.get_mapped(), 5, "the Go to list")
    gui.screen_shot("go-to-open")
    gui.key("Escape")
    pump(lambda: popover is not None and not popover.get_mapped(), 5, "the Go to list to close")
    gui.click(camera)
    pump(lambda: window.stack.get_visible_child_name() == "camera", 5, "the camera page")
    cycle = StopCycle(gui, sim)
    cycle.navigate()
    cycle.space_stops("navigating in full screen on the camera page")
    pump(lambda: cycle.mode() == "stop", 5, "the simulator's stop mode")
    cycle.navigate()  # and the full-screen bar's STOP, clicked
    before = cycle.stops()
    gui.click(bar.stop_button)
    pump(lambda: cycle.stops() > before, 5, "the full-screen bar's STOP to stop the robot")
    window.show_map()
    gui.focus()
    gui.key("F11")
    pump(lambda: not window.is_fullscreen() and not bar.get_reveal_child(), 10, "full screen to end")
    pump(lambda: inside(goto, header) and inside(camera, header), 5, "the buttons back in the header")
    pump(lambda: goto.get_mapped() and camera.get_mapped(), 5, "the header's buttons on screen")

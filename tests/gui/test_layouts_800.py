"""800×480 in split view and in the fleet view keeps the landscape window (issue 21, "Layouts").

The phone layout is for a narrow *window*; split view (video beside the map) and the fleet's robot
list make the map narrower, not the window. Before, the map stage's width decided, so both switched
an 800×480 window to the phone layout and lost the title and the title bar's buttons. Each test picks
its view with real input, looks at the header, and proves Space still stops (``StopCycle``).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import gi
import pytest

from rtmu.settings.store import DirectRobot
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.multi import SimFleetThreads, fleet_configs
from rtmu.ui.options import GuiOptions

from .harness import OFFICE_MAP, Gui, idle, on_display, pump, scratch_dir
from .stop_paths import MenuPicker, StopCycle, menu_entries
from .test_dpad_place import assert_in_corner_clear_of_the_zoom_row

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402


def stop_button_stops(gui: Gui, sim: SimThread) -> None:
    """The header's STOP, clicked during a navigation, stops the robot (the simulator's stop log)."""
    cycle = StopCycle(gui, sim)
    cycle.navigate()
    before = cycle.stops()
    gui.click(gui.window.stop_button)
    pump(lambda: cycle.stops() > before, 5, "STOP to stop the robot")


def assert_landscape(gui: Gui) -> None:
    """The window is laid out as at 800×480 always was: toolbar, title and window buttons."""
    window = gui.window
    assert window.get_width() >= 600, window.get_width()
    assert not window.handheld.layout.narrow, "the 800 px window switched to the phone layout"
    assert window.toolbar_revealer.get_visible(), "the status toolbar is gone"
    header = window.get_titlebar()
    assert isinstance(header, Gtk.HeaderBar)
    assert header.get_decoration_layout() != "", "the title bar lost its window buttons"
    title_box = window.title_label.get_parent()
    assert title_box is not None and title_box.get_visible(), "the title is gone"


def test_split_view_at_800x480_keeps_the_landscape_window(screenshots: Path, small_screen: str) -> None:
    with (
        SimThread(SimConfig(port=0, map_path=OFFICE_MAP, camera=True, seed=1)) as sim,
        on_display(small_screen),
    ):
        gui = Gui.start(screenshots, "split-800x480", "127.0.0.1", sim.port)
        try:
            entry = next(e for e in menu_entries(gui.window.menu_model) if e.action == "win.split")
            MenuPicker(gui).by_mouse(entry)
            split = gui.window.split
            pump(lambda: split.split and split.pane.get_mapped(), 5, "split view")
            idle(0.5)  # the idle switch of layout, had it been queued
            gui.screen_shot("split-view")
            assert_landscape(gui)
            StopCycle(gui, sim).prove("split view at 800x480", dpad_here=False)
            stop_button_stops(gui, sim)
        finally:
            gui.close()


@pytest.fixture
def fleet_sims() -> Iterator[list[SimThread]]:
    with SimFleetThreads(fleet_configs(SimConfig(port=0, map_path=OFFICE_MAP), 3)) as fleet:
        yield fleet.sims


def test_the_fleet_at_800x480_keeps_the_landscape_window(
    screenshots: Path, small_screen: str, fleet_sims: list[SimThread]
) -> None:
    robots = tuple(DirectRobot(f"robot{i + 1}", "127.0.0.1", s.port) for i, s in enumerate(fleet_sims))
    options = GuiOptions(
        fleet=robots, settings_path=scratch_dir("settings-") / "settings.toml", persist=False
    )
    with on_display(small_screen):
        gui = Gui.open(options, screenshots, "fleet-800x480")
        try:
            pump(lambda: len(gui.app.fleet) == 3, 10, "three robot sessions")
            pump(lambda: gui.app.fleet_binding is not None, 10, "the robot list")
            idle(0.5)
            gui.screen_shot("fleet")
            assert_landscape(gui)
            # The D-pad (View ▸ Touch D-pad, clicked) in its corner of the narrower map, off the zoom row.
            entry = next(e for e in menu_entries(gui.window.menu_model) if e.action == "win.dpad")
            MenuPicker(gui).by_mouse(entry)
            pump(lambda: gui.window.dpad.get_mapped(), 5, "the D-pad")
            idle(0.5)
            gui.screen_shot("fleet-dpad")
            assert_in_corner_clear_of_the_zoom_row(gui)
            StopCycle(gui, fleet_sims[0]).prove("the fleet view at 800x480")
            stop_button_stops(gui, fleet_sims[0])
        finally:
            gui.close()

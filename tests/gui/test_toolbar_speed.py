"""The status toolbar always shows the speed (issue 21, "Layouts").

A 1280×800 screen at ``GDK_SCALE=2`` gives a 640 px (logical) window: the toolbar gave up the
mm/s column second, so a robot navigating at 750 mm/s showed no speed anywhere. At 640 px, during a
real navigation, the speed column is on screen with the robot's speed, the row fits, and Space stops.
"""

from __future__ import annotations

from pathlib import Path

from rtmu.sim import SimConfig, SimThread

from .harness import OFFICE_MAP, Gui, pump
from .stop_paths import StopCycle


def test_the_speed_stays_in_the_toolbar_of_a_640px_window(screenshots: Path) -> None:
    with SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=1)) as sim:
        gui = Gui.start(screenshots, "toolbar-640", "127.0.0.1", sim.port)
        try:
            window, toolbar = gui.window, gui.window.toolbar
            window.set_default_size(640, 400)
            pump(lambda: window.get_width() <= 640, 5, "the window to shrink to 640 px")
            pump(lambda: bool(toolbar.hidden_columns()), 5, "minor columns to give way")
            cycle = StopCycle(gui, sim)
            cycle.navigate()
            speed = toolbar.cells["vel"]

            def shown_speed() -> int:
                text = speed.value.get_text()
                return int(text) if speed.get_mapped() and text.lstrip("-").isdigit() else 0

            pump(lambda: shown_speed() > 100, 10, "the speed of the navigating robot in the toolbar")
            assert not window.handheld.layout.narrow, "640 px is still the landscape window"
            assert toolbar.row.measure(0, -1)[0] <= toolbar.get_width(), "what is shown fits"
            gui.shot("navigating-at-640px")
            cycle.space_stops("navigating at 640 px")
            pump(lambda: cycle.mode() == "stop", 5, "the simulator's stop mode")
        finally:
            gui.close()

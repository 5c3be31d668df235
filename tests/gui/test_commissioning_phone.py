"""The commissioning windows on a phone: files, scan and map editing fit a 360×720 screen, nothing clipped.

Real window on a 360×720 X screen (the phone layout), real simulator with a map and a files folder. Each
window is opened by its action, as the menu does, and must fit the screen with every drawn widget inside
its surface — a field engineer commissions a robot from a tablet or a phone beside it as well.
"""

from __future__ import annotations

from pathlib import Path

import gi
import pytest

from rtmu.package_data import project_map
from rtmu.sim import SimThread
from simulators import simulator

from .harness import Gui, idle, on_display, pump
from .test_handheld_window import clipped_widgets

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

sim = simulator(map_path=project_map("office.map"), seed=1)


@pytest.mark.parametrize("action", ["files", "scan", "map-edit"])
def test_a_commissioning_window_fits_the_phone(
    action: str, screenshots: Path, phone_screen: str, sim: SimThread
) -> None:
    with on_display(phone_screen):
        gui = Gui.start(screenshots, f"phone-{action}", "127.0.0.1", sim.port)
        try:
            gui.wait_connected()
            pump(lambda: gui.window.handheld.layout.narrow, 5, "the phone layout")
            pump(lambda: bool(gui.model.map.value.name), 20, "the map")
            before = set(Gtk.Window.list_toplevels())

            def opened() -> list[Gtk.Window]:
                return [w for w in Gtk.Window.list_toplevels() if w not in before and w.get_mapped()]

            gui.window.activate_action(f"win.{action}", None)
            pump(lambda: bool(opened()), 5, f"win.{action} to open a window")
            idle(0.5)
            (surface,) = opened()
            gui.screen_shot(f"{action}-on-a-phone")
            width, height = surface.get_width(), surface.get_height()
            assert width <= 360 and height <= 720, f"{action}: {width}x{height} on a 360x720 screen"
            assert clipped_widgets(surface) == [], f"{action}: clipped widgets"
            surface.close()
            pump(lambda: not opened(), 5, "the window to close")
        finally:
            gui.close()

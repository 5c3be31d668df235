"""The real window against ``rtmu sim --kind aram``: laser layer, dock cell, routes panel, details and say.

And against the default profile: the LD controls stay hidden.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rtmu.sim import SimConfig, SimThread
from rtmu.sim.ld_data import ROUTES, ld_state

from .harness import OFFICE_MAP, Gui, pump


def magenta(pixels: np.ndarray) -> int:
    """How many stage pixels have RTMU's own laser colour (strong red and blue, little green)."""
    r, g, b = (pixels[..., i].astype(int) for i in range(3))
    return int(np.count_nonzero((r > 170) & (b > 90) & (g < 80)))


def laser_blue(pixels: np.ndarray) -> int:
    """Stage pixels in the colours the LD server's drawings give its lasers (0x0000FF and 0x0000C0)."""
    r, g, b = (pixels[..., i].astype(int) for i in range(3))
    return int(np.count_nonzero((r == 0) & (g == 0) & ((b == 255) | (b == 192))))


def _sim_state(sim: SimThread):  # type: ignore[no-untyped-def]
    return sim.call(lambda: ld_state(sim.server))  # type: ignore[arg-type]


def test_laser_dock_routes_and_say_in_the_window(screenshots: Path, request: pytest.FixtureRequest) -> None:
    with SimThread(SimConfig(port=0, profile="aram", map_path=OFFICE_MAP)) as sim:
        gui = Gui.start(screenshots, request.node.name, "127.0.0.1", sim.port)
        try:
            window, robot = gui.window, gui.model.robot
            pump(lambda: len(robot.value.laser) > 50, 5, "laser points in the model")
            # The server lists its lasers as drawings: they are drawn in its colours, not RTMU's magenta.
            pump(lambda: laser_blue(gui.stage_pixels()) > 30, 5, "laser points drawn on the stage")
            assert magenta(gui.stage_pixels()) == 0
            gui.shot("laser")
            # Both lasers switched off in the Layers panel: no laser pixel is left.
            window.activate_action("win.layers", None)
            layers = window.layers
            pump(
                lambda: layers.get_mapped() and {"Laser_1Current", "Laser_2Current"} <= set(layers.buttons),
                5,
                "layers",
            )
            for name in ("Laser_1Current", "Laser_2Current"):
                gui.click(layers.buttons[name])
            pump(lambda: laser_blue(gui.stage_pixels()) == 0, 5, "the laser layers to be hidden")
            for name in ("Laser_1Current", "Laser_2Current"):
                gui.click(layers.buttons[name])
            pump(lambda: laser_blue(gui.stage_pixels()) > 30, 5, "the lasers back")
            layers.close()

            dock = window.toolbar.cells["dock"]
            pump(lambda: dock.get_visible() and dock.value.get_text() == "Undocked", 5, "the dock cell")

            panel = window.routes_panel
            pump(lambda: panel.get_visible() and list(panel.rows) == list(ROUTES), 5, "the routes panel")
            panel.popup()
            gui.click(panel.rows[ROUTES[0]])
            pump(lambda: _sim_state(sim).patrols == [ROUTES[0]], 5, "the patrol at the simulator")

            window.show_details()
            details = window.details
            pump(lambda: "Wireless Quality" in details.values, 5, "the data-store table")
            assert details.values["Docking"].get_text() == "Undocked"
            assert details.say_row.get_visible()
            details.say_entry.set_text("Hello from the window")
            gui.click(details.say_button)
            pump(lambda: _sim_state(sim).said == ["Hello from the window"], 5, "the text at the simulator")
            gui.render(details, gui.shots / f"{gui.name}-details.png")
        finally:
            gui.close()


def test_default_profile_hides_the_ld_controls(screenshots: Path, request: pytest.FixtureRequest) -> None:
    with SimThread(SimConfig(port=0, map_path=OFFICE_MAP)) as sim:
        gui = Gui.start(screenshots, request.node.name, "127.0.0.1", sim.port)
        try:
            window = gui.window
            pump(lambda: len(gui.model.robot.value.sonar) > 0, 5, "sonar readings")
            assert not window.routes_panel.get_visible()
            assert not window.toolbar.cells["dock"].get_visible()
            assert magenta(gui.stage_pixels()) == 0
            window.show_details()
            assert not window.details.say_row.get_visible()
            # No DataStore_* values here: the table lists the server's own status strings instead.
            pump(lambda: "CPU Use" in window.details.values, 5, "the server's status strings")
            assert not window.details.none_label.get_visible()
            gui.shot("default-profile")
        finally:
            gui.close()


def test_route_goals_and_data_store_values_in_the_window(
    screenshots: Path, request: pytest.FixtureRequest
) -> None:
    """gotoRouteGoal from the routes popover's goal list; DataStore_* values in the toolbar: the
    localization score and closest obstacle in the mode cell's tooltip, the Wi-Fi gauge fed too."""
    with SimThread(SimConfig(port=0, profile="aram", map_path=OFFICE_MAP)) as sim:
        gui = Gui.start(screenshots, request.node.name, "127.0.0.1", sim.port)
        try:
            window, robot = gui.window, gui.model.robot
            panel = window.routes_panel
            pump(lambda: len(panel.goal_rows) > 0, 5, "the map's goals in the routes panel")
            goal = next(iter(panel.goal_rows))
            panel.popup()
            gui.shot("route-goals")
            gui.click(panel.goal_rows[goal])
            pump(lambda: _sim_state(sim).route_goals == [goal], 5, "gotoRouteGoal at the simulator")

            # The simulator's localization score as its data store reports it (0–100).
            served = sim.call(lambda: round(sim.server.world.localization.score * 100))
            assert 0 < served <= 100
            nav = gui.model.navigation
            pump(
                lambda: nav.value.loc_score is not None and abs(nav.value.loc_score * 100 - served) <= 0.5,
                5,
                "the localization score from the data store",
            )
            assert robot.value.wifi_quality is not None
            mode = window.toolbar.cells["mode"]
            tip = f"Localization score: {served} %"
            pump(lambda: tip in (mode.get_tooltip_text() or ""), 5, "the tooltip")
            assert "Closest obstacle:" in (mode.get_tooltip_text() or "")
        finally:
            gui.close()


def test_without_data_store_values_the_toolbar_says_nothing_of_them(
    screenshots: Path, request: pytest.FixtureRequest
) -> None:
    with SimThread(SimConfig(port=0, map_path=OFFICE_MAP)) as sim:
        gui = Gui.start(screenshots, request.node.name, "127.0.0.1", sim.port)
        try:
            mode = gui.window.toolbar.cells["mode"]
            pump(lambda: bool(mode.get_tooltip_text()), 5, "the mode cell's tooltip")
            gui.shot("no-data-store")
            assert "Closest obstacle" not in (mode.get_tooltip_text() or "")
            assert not gui.window.routes_panel.get_visible()
        finally:
            gui.close()

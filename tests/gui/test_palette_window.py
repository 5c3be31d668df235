"""The command palette in the real window: Ctrl+K, search, run a simple and a string command.

Real window, real simulator, real X keys. What is checked is the simulator's own state after the
command (its trip odometer, its battery voltage), the palette's filtering, the banner that says the
server took the command, and that the palette closes and gives the keyboard back for driving.
"""

from __future__ import annotations

from rtmu.control.commands import COMMANDS
from rtmu.sim import SimThread
from rtmu.ui.palette import CommandPalette
from simulators import simulator

from .harness import Gui, pump

sim = simulator(map_path=None, camera=False, seed=1)


def palette() -> CommandPalette | None:
    from gi.repository import Gtk

    return next(
        (w for w in Gtk.Window.list_toplevels() if isinstance(w, CommandPalette) and w.get_mapped()), None
    )


def in_entry(p: CommandPalette) -> bool:
    from gi.repository import Gtk

    focus = p.get_focus()
    return (
        focus is not None
        and focus.get_ancestor(Gtk.Entry) is not None
        and focus.get_ancestor(Gtk.SearchEntry) is None
    )


def open_palette(gui: Gui) -> CommandPalette:
    gui.focus()
    gui.key("ctrl+k")
    pump(lambda: palette() is not None, 5, "the palette")
    p = palette()
    assert p is not None
    pump(lambda: p.catalogue is not None, 5, "the server's commands")
    pump(lambda: p.search.has_focus() or p.is_active(), 3, "the palette to have the keys")
    return p


def test_the_palette_is_a_registry_command_with_ctrl_k_and_a_menu_item(gui: Gui) -> None:
    cmd = COMMANDS.get("server_commands")
    assert "<Control>k" in cmd.keys and cmd.menu
    labels = [gui.window.robot_menu.get_item_attribute_value(i, "label", None).get_string()
              for i in range(gui.window.robot_menu.get_n_items())]  # fmt: skip
    assert "Server commands…" in labels
    gui.shot("menu-has-it")


def test_search_and_run_a_simple_command(gui: Gui, sim: SimThread) -> None:
    world = sim.server.world  # type: ignore[union-attr]
    sim.call(lambda: setattr(world.body, "odometer_mm", 4321.0))
    p = open_palette(gui)
    names = p.visible_names()
    assert "ResetTripOdometer" in names and "SimulatorSetBattery" in names
    gui.xdotool("type", "--delay", "30", "trip odo")
    pump(lambda: p.visible_names() == ["ResetTripOdometer"], 3, "the search to leave one command")
    total = len(p.catalogue.commands)  # type: ignore[union-attr]
    assert p.note.get_text().startswith(f"1 of {total} commands"), p.note.get_text()
    gui.screen_shot("palette-search")
    gui.key("Return")
    pump(lambda: palette() is None, 3, "the palette to close")
    pump(lambda: sim.call(lambda: world.body.odometer_mm) < 100, 5, "the odometer to be reset")
    pump(lambda: "taken by the server" in (gui.window.banners.text("server-command") or ""), 5, "the banner")
    pump(gui.window.is_active, 3, "the keyboard back on the window")
    gui.shot("ran-reset")


def test_a_string_command_asks_for_its_argument_inline(gui: Gui, sim: SimThread) -> None:
    world = sim.server.world  # type: ignore[union-attr]
    p = open_palette(gui)
    gui.xdotool("type", "--delay", "30", "battery")
    gui.key("shift+space")  # in a text field Space stops the robot; Shift+Space types the space
    gui.xdotool("type", "--delay", "30", "voltage")
    pump(lambda: p.visible_names() == ["SimulatorSetBattery"], 3, "the search to leave one command")
    gui.key("Return")  # a string command: its argument field takes the keys first
    pump(lambda: in_entry(p), 3, "the argument field to have the keys")
    gui.xdotool("type", "--delay", "30", "11.7")
    gui.screen_shot("palette-argument")
    gui.key("Return")
    pump(lambda: palette() is None, 3, "the palette to close")
    pump(lambda: abs(sim.call(lambda: world.body.battery_v) - 11.7) < 0.05, 5, "the battery set to 11.7 V")
    gui.shot("ran-set-battery")


def test_escape_closes_the_palette_without_running_anything(gui: Gui, sim: SimThread) -> None:
    p = open_palette(gui)
    assert p.get_transient_for() is gui.window
    gui.key("Escape")
    pump(lambda: palette() is None, 3, "the palette to close")
    gui.shot("closed")

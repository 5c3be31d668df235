"""An Omron LD robot's configuration, told truthfully in the real window (``rtmu sim --profile aram``).

The 6MTX data list has ``getConfigValues`` and its family instead of ArConfig's: the Server menu's
Configuration row says which API the robot has and that RTMU cannot edit it yet; the configuration
page (opened by keyboard) says so in a sentence, and its button opens the console on the robot's
configuration data, where a read is called (the simulator lists it and never answers: "silent").
Space and the STOP button still stop with both pages open.
"""

from __future__ import annotations

from rtmu.sim import SimThread
from rtmu.ui.config_page import ConfigPage
from rtmu.ui.console_page import ConsolePage
from simulators import simulator

from .harness import Gui, pump
from .stop_paths import MenuEntry, MenuPicker, menu_entries, owned_windows
from .test_config_page import click

LD_ROW = "Configuration… — Omron LD's: not editable yet, see Console"
LD_DATA = ("getConfigValues", "setConfigValues", "updateConfigValues", "configExpandedSectionList")


sim = simulator(profile="aram", map_path=None, camera=False)


def stops(sim: SimThread) -> int:
    return sim.call(lambda: len(sim.server.stop_log))  # type: ignore[union-attr]


def owned(gui: Gui, kind: type) -> object:
    pump(lambda: any(isinstance(w, kind) for w in owned_windows(gui.window)), 5, kind.__name__)
    return next(w for w in owned_windows(gui.window) if isinstance(w, kind))


def _xid(window: object) -> int:
    from gi.repository import GdkX11

    return GdkX11.X11Surface.get_xid(window.get_surface())  # type: ignore[attr-defined]


def test_the_configuration_row_and_page_name_the_ld_api_and_point_at_the_console(
    gui: Gui, sim: SimThread
) -> None:
    listed = {e.name for e in sim.server.datalist}  # type: ignore[union-attr]
    assert "getConfigValues" in listed and not any(n.startswith("getConfigBySections") for n in listed)
    rows = {e.label: e for e in menu_entries(gui.window.menu_model) if e.path == ("Server",)}
    assert LD_ROW in rows and rows[LD_ROW].action == "win.server-config", list(rows)
    gui.focus()
    MenuPicker(gui).by_keyboard(MenuEntry(("Server",), "Configuration…", "win.server-config"))
    page = owned(gui, ConfigPage)
    assert isinstance(page, ConfigPage)
    pump(lambda: page.banner.get_visible() and page.console_button.get_visible(), 15, "the page's answer")
    said = page.banner.get_text()
    assert (
        "Omron LD's (getConfigValues, setConfigValues, updateConfigValues, configExpandedSectionList)" in said
    )
    assert "RTMU cannot show or edit it yet" in said and "Server ▸ Console…" in said, said
    gui.xdotool("windowmove", "--sync", str(_xid(page)), "380", "200")  # off the header bar: STOP in reach
    gui.render(page, gui.shots / f"{gui.name}-config.png")
    before = stops(sim)
    gui.click(gui.window.stop_button)
    pump(lambda: stops(sim) > before, 5, "the STOP button to stop with the configuration page open")
    gui.xdotool("windowfocus", "--sync", str(_xid(page)))
    click(gui, page.console_button)
    console = owned(gui, ConsolePage)
    assert isinstance(console, ConsolePage)
    pump(lambda: bool(console.entries) and not console.loading, 15, "the data list")
    names = [e.name for e in console.shown]
    assert {"getConfigValues", "setConfigValues", "updateConfigValues", "configExpandedSectionList"} <= set(
        names
    )
    assert console.search.get_text() == "config"
    gui.xdotool("windowmove", "--sync", str(_xid(console)), "420", "260")
    gui.xdotool("windowfocus", "--sync", str(_xid(console)))
    pump(console.is_active, 5, "the console to have the keyboard")
    before = stops(sim)
    gui.key("space")
    pump(lambda: stops(sim) > before, 5, "Space to stop with the console open")
    click(gui, console.rows.get_row_at_index(names.index("getConfigValues")))
    pump(lambda: console.current is not None and console.current.name == "getConfigValues", 3, "the pick")
    assert not console.current.changes  # type: ignore[union-attr]
    click(gui, console.call_button)
    pump(lambda: console.replies == 1, 20, "the call's outcome")
    buffer = console.reply.get_buffer()
    text = buffer.get_text(buffer.get_start_iter(), buffer.get_end_iter(), False)
    assert text.startswith("getConfigValues: silent"), text
    gui.render(console, gui.shots / f"{gui.name}-console.png")

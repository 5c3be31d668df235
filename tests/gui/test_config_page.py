"""The server configuration page in the real window: open, edit with real keys, save, see the server's answer.

Real window, real simulator, real X keys and clicks. What is checked is the simulator's own state
after a save (its watchdog timeout), the answer drawn next to each parameter (its words, and its
colour in the page's pixels), a change made by another client while an edit is pending, the
priority filter, keys typed in the page not driving the robot, and a hostile configuration of
10 000 parameters with markup in every text.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from rtmu.client.config_feed import set_config
from rtmu.client.connection import AriaClient
from rtmu.package_data import project_map
from rtmu.protocol.payloads.config import ParamType
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.arconfig import FILLER_CONTROL_SECTION
from rtmu.ui.config_page import PAGE_SIZE, ConfigPage
from rtmu.values.target import Target
from simulators import simulator

from .harness import Gui, LoopProbe, idle, pump, scratch_dir

sim = simulator(map_path=None, camera=False, seed=1)


def page(gui: Gui) -> ConfigPage | None:
    """The mapped configuration page of this test's window."""
    from gi.repository import Gtk

    return next(
        (
            w
            for w in Gtk.Window.list_toplevels()
            if isinstance(w, ConfigPage) and w.get_mapped() and w.get_transient_for() is gui.window
        ),
        None,
    )


def open_page(gui: Gui) -> ConfigPage:
    labels = []
    menu = gui.window.menu_model
    for i in range(menu.get_n_items()):
        section = menu.get_item_link(i, "section")
        for j in range(section.get_n_items()):
            sub = section.get_item_link(j, "submenu")
            label = section.get_item_attribute_value(j, "label", None)
            if sub is not None and label is not None and label.get_string() == "Server":
                labels += [
                    sub.get_item_attribute_value(k, "label", None).get_string()
                    for k in range(sub.get_n_items())
                ]
    assert labels == [
        "Connection settings…",
        "Configuration…",
        "Console…",
        "Files on the robot…",
        "Scan a map…",
        "Edit the map…",
    ]
    gui.window.activate_action("win.server-config", None)
    pump(lambda: page(gui) is not None, 5, "the configuration page")
    p = page(gui)
    assert p is not None and p.get_transient_for() is gui.window
    pump(lambda: p.config is not None and bool(p.rows), 15, "the configuration to load")
    return p


def choose_section(gui: Gui, p: ConfigPage, name: str) -> None:
    assert p.config is not None
    index = [s.name for s in p.config.sections].index(name)
    click(gui, p.sections.get_row_at_index(index))
    pump(lambda: p.current() is not None and p.current().name == name, 3, f"section {name}")  # type: ignore[union-attr]


def click(gui: Gui, widget) -> None:  # type: ignore[no-untyped-def]
    """A real click, the pointer first moved onto the widget's window (a page's first press after the pointer
    entered it is otherwise taken as the enter, under a bare X server)."""
    from gi.repository import GdkX11

    x, y = gui.centre_on_surface(widget)
    xid = str(GdkX11.X11Surface.get_xid(widget.get_native().get_surface()))
    gui.xdotool("mousemove", "--window", xid, str(x), str(y))
    idle(0.15)
    gui.click(widget)


def type_into(gui: Gui, widget, text: str, leave: bool = True) -> None:  # type: ignore[no-untyped-def]
    """Real keys into ``widget``: its window gets the X focus, the widget GTK's, then ctrl+a and the text."""
    from gi.repository import GdkX11

    root = widget.get_root()
    gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(root.get_surface())))
    pump(root.is_active, 5, "the page to have the keyboard")
    widget.grab_focus()
    pump(lambda: _focus_in(root, widget), 3, "the editor to have the keys")
    gui.key("ctrl+a")
    gui.xdotool("type", "--delay", "40", text)
    if leave:
        gui.key("Tab")  # leave the field, as an operator does: a spin button takes its text then


def labels(widget) -> list[tuple[str, bool]]:  # type: ignore[no-untyped-def]
    """Every label under ``widget``: (its text, whether it is read as markup)."""
    from gi.repository import Gtk

    out = [(widget.get_text(), widget.get_use_markup())] if isinstance(widget, Gtk.Label) else []
    child = widget.get_first_child()
    while child is not None:
        out += labels(child)
        child = child.get_next_sibling()
    return out


def _focus_in(root, widget) -> bool:  # type: ignore[no-untyped-def]
    focus = root.get_focus()
    return focus is not None and (focus is widget or focus.is_ancestor(widget))


def answer(p: ConfigPage, section: str, name: str) -> str:
    return p.rows[(section, name)][2].get_text()


def red_and_green(gui: Gui, widget) -> tuple[int, int]:  # type: ignore[no-untyped-def]
    """Pixels of ``widget`` that are clearly red, clearly green (the page's error and success colours)."""
    path = gui.render(widget, scratch_dir("config-") / "answer.png")
    with Image.open(path) as img:
        rgb = np.asarray(img.convert("RGB")).astype(int)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return int(((r > 150) & (r > g + 60) & (r > b + 60)).sum()), int(
        ((g > 100) & (g > r + 40) & (g > b + 20)).sum()
    )


def test_edit_save_accepted_then_a_refused_value_shows_the_servers_error(gui: Gui, sim: SimThread) -> None:
    p = open_page(gui)
    names = [s.name for s in p.config.sections]  # type: ignore[union-attr]
    assert names == ["Teleop", "Robot config", "Camera", "Battery", "Wi-Fi", "Files"]
    gui.render(p, gui.shots / f"{gui.name}-opened.png")
    _param, spin, _label = p.rows[("Teleop", "Timeout")]
    type_into(gui, spin, "0.5")
    pump(lambda: p.edits.get(("Teleop", "Timeout")) == "0.50", 3, "the edit to be noted")
    assert answer(p, "Teleop", "Timeout") == "edited" and p.save_button.get_sensitive()
    click(gui, p.save_button)
    pump(lambda: answer(p, "Teleop", "Timeout") == "✓ accepted", 5, "the server to accept")
    assert sim.call(lambda: sim.server.world.ratio_mode.timeout) == 0.5  # type: ignore[union-attr]
    assert not p.edits and not p.save_button.get_sensitive()
    red, green = red_and_green(gui, p.rows[("Teleop", "Timeout")][2])
    assert green > 20 and red == 0
    gui.render(p, gui.shots / f"{gui.name}-accepted.png")
    _change_from_another_client(sim, {"Teleop": {"Timeout": "4"}})
    pump(lambda: answer(p, "Teleop", "Timeout") == "", 5, "the tick to go once another value is held")
    fetches = p.fetches
    _change_from_another_client(sim, {"Teleop": {"Timeout": "0.5"}})  # back, for what follows
    pump(lambda: p.fetches > fetches and not p.fetching, 5, "the page to fetch again")

    _param, spin, _label = p.rows[("Teleop", "Timeout")]
    type_into(gui, spin, "0.05")  # within the limits, refused by the server for its own reason
    pump(lambda: p.edits.get(("Teleop", "Timeout")) == "0.05", 3, "the second edit")
    click(gui, p.save_button)
    expected = (
        "✗ Teleop/Timeout: 0.05 s is shorter than the 0.1 s between ratioDrive commands (0 disables it)"
    )
    pump(lambda: answer(p, "Teleop", "Timeout") == expected, 5, "the server's refusal")
    assert p.edits == {("Teleop", "Timeout"): "0.05"}  # the refused edit is kept, not lost
    assert sim.call(lambda: sim.server.world.ratio_mode.timeout) == 0.5  # type: ignore[union-attr]
    red, _green = red_and_green(gui, p.rows[("Teleop", "Timeout")][2])
    assert red > 20
    gui.render(p, gui.shots / f"{gui.name}-refused.png")
    gui.shot("main-window-behind")


def _change_from_another_client(sim: SimThread, changes: dict[str, dict[str, str]]) -> None:
    import asyncio

    async def other() -> str:
        client = AriaClient()
        await client.connect(Target("127.0.0.1", sim.port), timeout=5)
        try:
            return (await set_config(client, changes, 5)).error
        finally:
            await client.disconnect()

    assert asyncio.run(other()) == ""


def test_inline_validation_blocks_save_and_typing_never_drives(gui: Gui, sim: SimThread) -> None:
    p = open_page(gui)
    choose_section(gui, p, "Robot config")
    _param, spin, _label = p.rows[("Robot config", "TransVelMax")]
    type_into(gui, spin, "99999", leave=False)
    pump(lambda: answer(p, "Robot config", "TransVelMax") == "✗ above the maximum of 1500", 3, "inline error")
    assert not p.save_button.get_sensitive()
    red, _green = red_and_green(gui, p.rows[("Robot config", "TransVelMax")][2])
    assert red > 20
    gui.render(p, gui.shots / f"{gui.name}-inline.png")
    gui.key("Tab")  # never clamped to 1500 without a word: the held value stays, the row says why
    pump(lambda: not p.edits, 3, "the wrong edit to go")
    said = answer(p, "Robot config", "TransVelMax")
    assert said.startswith("✗ 99999 not taken: above the maximum of 1500 (still "), said
    assert spin.get_value() != 1500 or said.endswith("(still 1500)"), "clamped to the limit"
    gui.render(p, gui.shots / f"{gui.name}-refused-in-words.png")
    gui.key("Up", "Up", "w", "space")  # drive keys in the main window; here they only edit
    idle(0.5)
    robot = sim.call(lambda: (sim.server.robot.vel, sim.server.world.ratio_mode.trans_ratio))  # type: ignore[union-attr]
    assert robot == (0, 0)
    assert sim.call(lambda: sim.server.world.mode.NAME) != "ratioDrive"  # type: ignore[union-attr]
    gui.key("Escape")
    if p.edits:  # Up in a spin button edits it: Escape asks before the edit is lost
        pump(lambda: p.discard.asking, 3, "the discard question")
        click(gui, p.discard.discard_button)
    pump(lambda: page(gui) is None, 3, "Escape to close the page")
    gui.shot("closed")


def test_escape_with_an_unsaved_edit_asks_before_discarding_it(gui: Gui, sim: SimThread) -> None:
    p = open_page(gui)
    _param, spin, _label = p.rows[("Teleop", "Timeout")]
    type_into(gui, spin, "0.7")
    pump(lambda: p.edits.get(("Teleop", "Timeout")) == "0.70", 3, "the edit")
    gui.key("Escape")
    pump(lambda: p.discard.asking, 3, "the question")
    assert page(gui) is p and p.edits == {("Teleop", "Timeout"): "0.70"}, "closed or lost the edit"
    assert "1 unsaved edit" in p.discard.label.get_text()
    gui.render(p, gui.shots / f"{gui.name}-asks.png")
    stops = sim.call(lambda: len(sim.server.stop_log))  # type: ignore[union-attr]
    gui.key("space")  # the stop key still stops while the page asks (and answers nothing)
    pump(lambda: sim.call(lambda: len(sim.server.stop_log)) > stops, 3, "Space to send a stop")  # type: ignore[union-attr]
    assert p.discard.asking and page(gui) is p, "Space answered the question"
    gui.key("Escape")  # answers "keep editing"
    pump(lambda: not p.discard.asking, 3, "the question to go")
    assert page(gui) is p and p.edits
    p.close()  # the title bar's close asks too
    pump(lambda: p.discard.asking, 3, "the question on close")
    assert page(gui) is p
    click(gui, p.discard.discard_button)
    pump(lambda: page(gui) is None, 3, "Discard and close to close the page")
    assert sim.call(lambda: sim.server.world.ratio_mode.timeout) != 0.7  # type: ignore[union-attr]


def test_another_clients_change_refreshes_without_losing_an_edit(gui: Gui, sim: SimThread) -> None:
    p = open_page(gui)
    choose_section(gui, p, "Camera")
    drop = p.rows[("Camera", "FrameSize")][1]
    drop.set_selected(1)  # 640x480, unsaved
    pump(lambda: p.edits.get(("Camera", "FrameSize")) == "640x480", 3, "the pending edit")
    fetches = p.fetches

    async def other() -> str:
        client = AriaClient()
        await client.connect(Target("127.0.0.1", sim.port), timeout=5)
        try:
            reply = await set_config(
                client, {"Camera": {"FrameSize": "320x240"}, "Teleop": {"Timeout": "3"}}, 5
            )
            return reply.error
        finally:
            await client.disconnect()

    import asyncio

    assert asyncio.run(other()) == ""
    pump(lambda: p.fetches > fetches, 5, "the page to fetch again on configUpdated")
    text = p.banner.get_text()
    assert p.banner.get_visible() and "Another client changed Teleop/Timeout (now 3)" in text
    assert p.edits == {("Camera", "FrameSize"): "640x480"}  # kept
    assert p.rows[("Camera", "FrameSize")][1].get_selected() == 1
    gui.render(p, gui.shots / f"{gui.name}-remote-change.png")
    # now a change to the very value being edited: the banner says so
    fetches = p.fetches

    async def clash() -> str:
        client = AriaClient()
        await client.connect(Target("127.0.0.1", sim.port), timeout=5)
        try:
            return (await set_config(client, {"Camera": {"FrameSize": "640x480"}}, 5)).error
        finally:
            await client.disconnect()

    assert asyncio.run(clash()) == ""
    pump(lambda: p.fetches > fetches, 5, "the second refresh")
    assert "Camera/FrameSize (now 640x480)" in p.banner.get_text()
    assert not p.edits  # the other client set exactly this value: nothing left to save
    gui.shot("after-remote")


def test_the_priority_filter_hides_expert_parameters(gui: Gui, sim: SimThread) -> None:
    p = open_page(gui)
    choose_section(gui, p, "Wi-Fi")
    assert len(p.rows) == 3
    p.priority.set_selected(0)  # Basic
    pump(lambda: not p.rows, 3, "the expert parameters to be hidden")
    assert "3 above basic hidden" in p.page_label.get_text()
    gui.render(p, gui.shots / f"{gui.name}-basic.png")
    choose_section(gui, p, "Robot config")
    p.priority.set_selected(4)  # Factory: the serial number is shown, read-only
    pump(lambda: ("Robot config", "SerialNumber") in p.rows, 3, "the factory parameter")
    assert not p.rows[("Robot config", "SerialNumber")][1].get_sensitive()
    gui.shot("factory")


hostile = simulator(map_path=None, camera=False, config_filler=10_000)


def test_ten_thousand_parameters_with_markup_open_bounded_and_responsive(
    screenshots: Path, hostile: SimThread
) -> None:
    gui = Gui.start(screenshots, "config-hostile", "127.0.0.1", hostile.port)
    try:
        p = open_page(gui)
        served = hostile.call(  # every parameter the simulator serves but its separators (only a line)
            lambda: sum(q.template.kind is not ParamType.SEPARATOR for q in hostile.server.arconfig.params)  # type: ignore[union-attr]
        )
        assert served > 10_000 and p.config is not None and p.config.param_count == served
        choose_section(gui, p, "<b>Extra</b> & 0")
        pump(lambda: len(p.rows) == PAGE_SIZE, 5, "one page of rows")
        shown = labels(p.grid)
        assert ("P0<i>&amp;", False) in shown and ("<u>filler</u> 0 & <big>text</big>", False) in shown
        assert ("<b>7</b>", False) in shown  # a choice list's item, as the drop-down shows it
        assert not any(markup for _text, markup in shown)
        assert p.sections.get_row_at_index(6).get_child().get_text() == "<b>Extra</b> & 0"
        assert p.comment.get_text() == "<i>filler</i> & <span foreground='red'>markup</span>"
        names = [p.sections.get_row_at_index(i).get_child().get_text() for i in range(len(p.config.sections))]
        assert "Line\\rbreak\\nand \\x1b[2Jescape" in names, names  # one line, its controls shown
        assert not any(c in name for name in names for c in "\r\n\x1b")
        choose_section(gui, p, FILLER_CONTROL_SECTION)
        pump(lambda: len(p.rows) == 1, 5, "the section with control characters")
        assert ("Line\\rbreak", False) in labels(p.grid)
        choose_section(gui, p, "<b>Extra</b> & 0")
        probe = LoopProbe()
        click(gui, p.next_button)
        pump(lambda: p.page_label.get_text() == "61–120 of 800 (200 above expert hidden)", 5, "the next page")
        idle(0.5)
        probe.close()
        assert probe.beats > 0  # the main loop kept running
        assert len(p.rows) == PAGE_SIZE  # a page of widgets, whatever the size of the section
        gui.render(p, gui.shots / "config-hostile-page2.png")
        gui.shot("main-window")
    finally:
        gui.close()


def test_an_ld_robots_configuration_is_named_and_not_offered_for_editing(screenshots: Path) -> None:
    """Protocol 6MTX lists Omron LD's getConfigValues family, not ArConfig's: the page says which API
    the robot has and that RTMU cannot edit it yet, instead of an empty page or "none offered"."""
    office = project_map("office.map")
    with SimThread(SimConfig(port=0, profile="aram", map_path=office)) as aram:
        gui = Gui.start(screenshots, "config-ld", "127.0.0.1", aram.port)
        try:
            gui.window.activate_action("win.server-config", None)
            pump(lambda: page(gui) is not None, 5, "the configuration page")
            p = page(gui)
            assert p is not None
            pump(lambda: p.banner.get_visible(), 10, "the page to name the robot's API")
            text = p.banner.get_text()
            assert "Omron LD's" in text and "getConfigValues" in text and "cannot show or edit it yet" in text
            assert p.status.get_text() == "No configuration RTMU can edit"
            assert p.config is None and not p.rows
            gui.render(p, gui.shots / "config-ld.png")
        finally:
            gui.close()

"""The console page in the real window: the server's whole data list, a filter, one call, its reply.

Real window, real simulator (or a hostile test server), real X keys and clicks. Opened from the
menu by keyboard; every data the simulator lists is there; a filter typed with real keys narrows it;
a read is called and its reply shown as bytes, fields and RTMU's own type; a call that changes
something (the simulator's stall command) asks first and nothing reaches the simulator before the
yes; ``ratioDrive`` cannot be called. Space and the STOP button stop the robot with the page and its
confirmation open. A hostile server's floods and endless replies are shown bounded and the window
keeps running.
"""

from __future__ import annotations

from pathlib import Path

from client.servers import ServerThread
from client.test_console import FLOOD_PACKETS, hostile_server
from rtmu.sim import SimThread
from rtmu.ui.console_page import MAX_LINES, MAX_ROWS, ConsolePage, matches
from simulators import simulator

from .harness import Gui, LoopProbe, idle, pump
from .stop_paths import MenuEntry, MenuPicker, owned_windows
from .test_config_page import click, type_into

CONSOLE_ROW = MenuEntry(("Server",), "Console…", "win.console")


sim = simulator(map_path=None, camera=False, seed=1)


def stops(sim: SimThread) -> int:
    return sim.call(lambda: len(sim.server.stop_log))  # type: ignore[union-attr]


def open_console(gui: Gui) -> ConsolePage:
    gui.focus()
    MenuPicker(gui).by_keyboard(CONSOLE_ROW)
    pump(lambda: any(isinstance(w, ConsolePage) for w in owned_windows(gui.window)), 5, "the console")
    page = next(w for w in owned_windows(gui.window) if isinstance(w, ConsolePage))
    pump(lambda: bool(page.entries) and not page.loading, 15, "the data list")
    # No window manager places it: moved off the header bar, as an operator would, so STOP stays in reach.
    gui.xdotool("windowmove", "--sync", str(_xid(page)), "380", "200")
    return page


def pick(gui: Gui, page: ConsolePage, name: str) -> None:
    """Type ``name`` into the filter with real keys, then click its row."""
    type_into(gui, page.search, name, leave=False)
    names = lambda: [e.name for e in page.shown]  # noqa: E731
    # The entry filters a moment after each key: a list of the first letters can hold the row too,
    # and is rebuilt under the pointer. Only the list of the whole name is clicked in.
    whole = [e.name for e in page.entries if matches(e, name)][:MAX_ROWS]
    pump(
        lambda: page.search.get_text() == name and names() == whole and len(whole) < len(page.entries),
        5,
        f"the filter to find {name}",
    )
    click(gui, page.rows.get_row_at_index(names().index(name)))
    pump(lambda: page.current is not None and page.current.name == name, 3, f"{name} to be picked")


def reply(page: ConsolePage) -> str:
    buffer = page.reply.get_buffer()
    return buffer.get_text(buffer.get_start_iter(), buffer.get_end_iter(), False)


def test_the_whole_list_a_filter_and_a_read(gui: Gui, sim: SimThread) -> None:
    page = open_console(gui)
    listed = [e.name for e in sim.server.datalist]  # type: ignore[union-attr]
    assert [e.name for e in page.entries] == listed and len(listed) > 50
    assert page.count.get_text() == f"{len(listed)} of {len(listed)} data"
    gui.render(page, gui.shots / f"{gui.name}-list.png")
    pick(gui, page, "getModeInfo")
    assert "Effect: read" in page.details.get_text() and page.call_button.get_label() == "Call once"
    click(gui, page.call_button)
    pump(lambda: page.replies == 1, 10, "the reply")
    text = reply(page)
    assert text.startswith("getModeInfo: replied: 1 packet") and "as ModeInfo:" in text, text
    assert "packet 1 (" in text and not page.confirm.asking
    gui.render(page, gui.shots / f"{gui.name}-read.png")


def test_a_change_asks_first_ratio_drive_never_and_stop_works(gui: Gui, sim: SimThread) -> None:
    page = open_console(gui)
    pick(gui, page, "ratioDrive")
    assert not page.call_button.get_sensitive() and "never sent from the console" in page.status.get_text()
    pick(gui, page, "SimulatorStallMotors")
    assert "changes something" in page.details.get_text()
    page.arguments.grab_focus()
    gui.key("Return")  # Return in the arguments calls: this one only asks
    pump(lambda: page.confirm.asking and page.confirm.cancel_button.has_focus(), 5, "the confirmation")
    gui.render(page, gui.shots / f"{gui.name}-confirm.png")
    idle(0.5)
    assert not sim.snapshot().stalled and page.replies == 0  # nothing sent before the yes
    gui.key("Escape")  # Esc in the confirmation cancels it
    pump(lambda: not page.confirm.asking, 3, "Esc to cancel the confirmation")
    page.arguments.grab_focus()
    gui.key("Return")
    pump(lambda: page.confirm.asking, 5, "the confirmation again")
    for how in ("Space", "the STOP button"):
        before = stops(sim)
        if how == "Space":
            gui.key("space")
        else:
            gui.click(gui.window.stop_button)
        pump(lambda before=before: stops(sim) > before, 5, f"{how} to stop with the console open")
    assert not sim.snapshot().stalled
    gui.xdotool("windowfocus", "--sync", str(_xid(page)))
    if not page.confirm.asking:
        click(gui, page.call_button)
    pump(lambda: page.confirm.asking, 5, "the confirmation again")
    click(gui, page.confirm.yes_button)
    pump(lambda: sim.snapshot().stalled, 10, "the simulator's motors to stall")
    pump(lambda: page.replies == 1, 10, "the outcome")
    assert reply(page).startswith("SimulatorStallMotors: taken")
    gui.render(page, gui.shots / f"{gui.name}-sent.png")


def followed_at(sim: SimThread) -> set[str]:
    server = sim.server
    assert server is not None
    return sim.call(lambda: {sub.name for s in server.sessions for sub in s.subscriptions.values()})


def test_a_read_is_followed_at_an_interval_until_switched_off_and_a_change_never(
    gui: Gui, sim: SimThread
) -> None:
    page = open_console(gui)
    pick(gui, page, "SimulatorStallMotors")
    assert not page.follow_button.get_sensitive(), "a data that changes something must not be followed"
    pick(gui, page, "update")
    assert page.follow_button.get_sensitive()
    type_into(gui, page.interval, "200")
    pump(lambda: page.interval.get_value() == 200, 3, "the interval typed in")
    click(gui, page.follow_button)
    pump(lambda: page.followed >= 3, 10, "three replies of the followed data")
    assert "update" in followed_at(sim) and not page.interval.get_sensitive()
    assert " replies, the last at " in page.follow_status.get_text(), page.follow_status.get_text()
    assert reply(page).startswith("update: "), reply(page)[:200]
    gui.render(page, gui.shots / f"{gui.name}-following.png")
    before = stops(sim)
    gui.key("space")  # the stop key still stops while a data is followed
    pump(lambda: stops(sim) > before, 5, "Space to stop while following")
    click(gui, page.follow_button)  # off
    pump(lambda: "update" not in followed_at(sim), 5, "the server to stop sending it")
    idle(0.6)
    seen = page.followed
    idle(1.0)
    assert page.followed == seen and page.follow_status.get_text() == "stopped following update"
    assert page.interval.get_sensitive()


def test_hostile_replies_are_shown_bounded(screenshots: Path) -> None:
    with ServerThread(hostile_server()) as server:
        gui = Gui.start(screenshots, "test_console_hostile", "127.0.0.1", server.port)
        try:
            page = open_console(gui)
            pick(gui, page, "manyFields")
            click(gui, page.call_button)
            pump(lambda: page.replies == 1, 30, "the flood's reply")
            lines = reply(page).splitlines()
            assert len(lines) <= MAX_LINES + 1 and lines[0].startswith("manyFields: replied")
            assert sum("more fields" in line for line in lines) == FLOOD_PACKETS
            probe = LoopProbe()
            pick(gui, page, "endless")
            click(gui, page.call_button)
            pump(lambda: page.replies == 2, 30, "the endless reply to be cut")
            assert reply(page).startswith("endless: cut"), reply(page)[:200]
            assert len(reply(page).splitlines()) <= MAX_LINES + 1
            pump(lambda: probe.beats > 5, 5, "the window to keep running")
            probe.close()
            gui.render(page, gui.shots / f"{gui.name}-cut.png")
        finally:
            gui.close()


def _xid(window: object) -> int:
    from gi.repository import GdkX11

    return GdkX11.X11Surface.get_xid(window.get_surface())  # type: ignore[attr-defined]

"""The status cells' tooltips: shown under a real pointer, new words shown without moving it (issue 28).

A cell's tooltip is answered when GTK asks for it: setting GTK's own tooltip text made GTK query the
tooltip under the pointer each time, and the link cell's words change every second (its round trip,
the status's age), which cost a still window 2–10 ms of every second. Here the operator's pointer
rests on the link cell: the tooltip shows the cell's words, and when they change the tooltip on
screen says so without the pointer moving. Space still stops with the tooltip up.
"""

from __future__ import annotations

import gi

from rtmu.sim import SimThread
from rtmu.ui.stop_keys import descendants
from simulators import simulator

from .harness import Gui, pump

gi.require_version("Gtk", "4.0")
from gi.repository import GdkX11, Gtk  # noqa: E402

sim = simulator(map_path=None, camera=False, seed=1)


def tooltip_on_screen(window: Gtk.Window) -> str | None:
    """The words of the tooltip shown now (its window is the main window's child while it shows)."""
    for widget in descendants(window):
        if widget.get_css_name() == "tooltip" and widget.get_mapped():
            labels = [w for w in descendants(widget) if isinstance(w, Gtk.Label) and w.get_mapped()]
            return "\n".join(label.get_text() for label in labels)
    return None


def stops(sim: SimThread) -> int:
    return sim.call(lambda: len(sim.server.stop_log))  # type: ignore[union-attr]


def test_a_resting_pointer_shows_the_cells_words_and_their_change(gui: Gui, sim: SimThread) -> None:
    window = gui.window
    cell = window.toolbar.cells["link"]
    pump(lambda: "round trip" in (cell.get_tooltip_text() or ""), 10, "the link's words")
    # GTK's own tooltip text stays empty: a refresh never makes GTK query the tooltip under the pointer
    for name, each in window.toolbar.cells.items():
        assert Gtk.Widget.get_tooltip_text(each) is None, name
    assert cell.get_has_tooltip()

    gui.focus()
    x, y = gui.centre_on_surface(cell)
    xid = str(GdkX11.X11Surface.get_xid(window.get_surface()))
    gui.xdotool("mousemove", "--window", xid, str(x - 2), str(y))
    gui.xdotool("mousemove", "--window", xid, str(x), str(y))  # a motion inside the cell: GTK times the tip
    pump(lambda: tooltip_on_screen(window) == cell.get_tooltip_text(), 10, "the link's tooltip")
    first = tooltip_on_screen(window)
    gui.screen_shot("link-tooltip")

    # The round trip (to 0.1 ms) and the learned limit change as pings come back, once a second.
    pump(lambda: cell.get_tooltip_text() != first, 30, "the link's words to change")
    pump(lambda: tooltip_on_screen(window) == cell.get_tooltip_text(), 5, "the tooltip to say so, unmoved")
    gui.screen_shot("link-tooltip-later")

    count = stops(sim)
    gui.key("space")  # the stop key with a tooltip up
    pump(lambda: stops(sim) > count, 5, "Space to stop with the tooltip up")

"""The paths to the stop key, for the GUI tests: the menu model read as data, picks by mouse and by
keyboard (real X events), and the proof cycle that follows each pick.

The cycle (:meth:`StopCycle.prove`) is what issue 21 asks after every pick: with the window in the
state the pick left it, the robot navigates and Space stops it (the simulator logs the ``stop``);
a D-pad drive held with the mouse and Space stops it; then, back on the map, a held Up drives again.
What is checked is what the simulator received, not what the window believes.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Iterator
from dataclasses import dataclass

import gi

from rtmu.sim import SimThread
from rtmu.ui.dialog_chain import dialogs_of
from rtmu.ui.stop_keys import descendants
from rtmu.values.intents import GotoGoal

from .harness import Gui, idle, pump

gi.require_version("Gtk", "4.0")
from gi.repository import Gio, GLib, Gtk  # noqa: E402

GOALS = ("Lab B", "Meeting Room")
"""Far goals of data/maps/office.map: the robot never arrives before Space."""


@dataclass(frozen=True)
class MenuEntry:
    """One item of a menu model: the submenus leading to it, its label and its action."""

    path: tuple[str, ...]
    label: str
    action: str
    target: GLib.Variant | None = None

    @property
    def name(self) -> str:
        return " ▸ ".join((*self.path, self.label))


def _attr(model: Gio.MenuModel, i: int, name: str) -> str:
    value = model.get_item_attribute_value(i, name, None)
    return value.get_string() if value is not None else ""


def menu_entries(model: Gio.MenuModel, path: tuple[str, ...] = ()) -> Iterator[MenuEntry]:
    """Every item that runs an action, depth first, as the menu shows them (sections flattened)."""
    for i in range(model.get_n_items()):
        section = model.get_item_link(i, "section")
        submenu = model.get_item_link(i, "submenu")
        if section is not None:
            yield from menu_entries(section, path)
        elif submenu is not None:
            yield from menu_entries(submenu, (*path, _attr(model, i, "label")))
        elif action := _attr(model, i, "action"):
            target = model.get_item_attribute_value(i, "target", None)
            yield MenuEntry(path, _attr(model, i, "label"), action, target)


def label_of(widget: Gtk.Widget) -> str:
    return next((d.get_label() for d in descendants(widget) if isinstance(d, Gtk.Label)), "")


def model_button(popover: Gtk.Widget, label: str) -> Gtk.Widget | None:
    """The menu row (a GtkModelButton) showing ``label`` on screen now."""
    for widget in descendants(popover):
        if widget.get_css_name() == "modelbutton" and widget.get_mapped() and label_of(widget) == label:
            return widget
    return None


def current_label(window: Gtk.Window, entry: MenuEntry) -> str:
    """The entry's label as the menu says it now (a robot command's label carries its state)."""
    for now in menu_entries(window.menu_model):  # type: ignore[attr-defined]
        if now.action == entry.action and now.path == entry.path and now.target == entry.target:
            return now.label
    return entry.label


def owned_windows(window: Gtk.Window) -> list[Gtk.Window]:
    """The window's dialogs that are on screen (their transient-for chain leads to it)."""
    return [other for other in dialogs_of(window) if other.get_mapped()]


class MenuPicker:
    """Picks menu entries with real X input: clicks, or F10 and arrow keys and Return."""

    def __init__(self, gui: Gui) -> None:
        self.gui = gui

    @property
    def popover(self) -> Gtk.Popover:
        popover = self.gui.window.menu_button.get_popover()
        assert popover is not None
        return popover

    def by_mouse(self, entry: MenuEntry) -> None:
        gui, popover = self.gui, self.popover
        gui.click(gui.window.menu_button)
        pump(popover.get_mapped, 3, "the menu")
        for sub in entry.path:
            opener = model_button(popover, sub)
            assert opener is not None, f"no submenu row {sub!r}"
            gui.click(opener)
        label = current_label(gui.window, entry)
        pump(lambda: model_button(popover, label) is not None, 3, f"the row {entry.name!r}")
        row = model_button(popover, label)
        assert row is not None and row.get_sensitive(), f"{entry.name} cannot be picked"
        gui.click(row)

    def by_keyboard(self, entry: MenuEntry, tries: int = 3) -> None:
        """F10, the arrow keys and Return down ``entry``'s path, then Return on its row.

        When the row does not show (CI, once: "Server ▸" entered with Return, "Console…" never
        shown; cause not found — perhaps the menu's model changing while open, just after the
        connection), the menu is closed with Escape and walked again, as an operator would; the
        last try's failure is the test's."""
        gui, popover = self.gui, self.popover
        for attempt in range(tries):
            gui.key("F10")
            pump(popover.get_mapped, 3, "F10 to open the menu")
            try:
                for sub in entry.path:
                    self._focus_row(sub)
                    gui.key("Return")
                self._focus_row(current_label(gui.window, entry))
                break
            except AssertionError:
                if attempt == tries - 1:
                    raise
                for _ in range(5):  # a submenu's Escape may go back a page first
                    if not popover.get_mapped():
                        break
                    gui.key("Escape")
                    with contextlib.suppress(AssertionError):
                        pump(lambda: not popover.get_mapped(), 1, "Escape to close the menu")
        gui.key("Return")

    def _focus_row(self, label: str) -> None:
        """Down or Up, towards the row showing ``label``, until it has the focus."""
        gui, popover = self.gui, self.popover
        pump(lambda: model_button(popover, label) is not None, 3, f"the row {label!r}")
        row = model_button(popover, label)
        for _ in range(40):
            focus = gui.window.get_focus()
            if focus is row:
                return
            # Towards the row from where the focus is: a key a busy machine ran late, and the next one
            # with it, moves past the row; the next key comes back (Down alone went round the menu).
            rows = [w for w in descendants(popover) if w.get_css_name() == "modelbutton" and w.get_mapped()]
            above = focus in rows and row in rows and rows.index(focus) > rows.index(row)
            gui.key("Up" if above else "Down")
            # One key at a time: the next is pressed only once this one has moved the focus. Pressed
            # blind every 20 ms, keys queued on a busy machine ran past the row and round again.
            with contextlib.suppress(AssertionError):
                pump(lambda f=focus: gui.window.get_focus() is not f, 2, "the focus to move")
        raise AssertionError(f"the keyboard never reached the row {label!r}")


class StopCycle:
    """Space stops a navigation and a held D-pad drive; a held Up drives again (module notes)."""

    def __init__(self, gui: Gui, sim: SimThread) -> None:
        self.gui = gui
        self.sim = sim
        self.proved: list[str] = []
        self.latencies: list[float] = []
        """Seconds from each Space (xdotool started) to the simulator's stop log growing."""
        self._goal = 0

    def stops(self) -> int:
        return self.sim.call(lambda: len(self.sim.server.stop_log))

    def mode(self) -> str:
        return self.sim.snapshot().mode_name

    def driven(self) -> bool:
        snap = self.sim.snapshot()
        return snap.mode_name == "ratioDrive" and snap.trans_ratio > 0 and snap.throttle_ratio > 0

    def space_stops(self, what: str) -> None:
        before = self.stops()
        pressed = time.monotonic()
        self.gui.key("space")
        pump(lambda: self.stops() > before, 5, f"Space to stop the robot {what}")
        self.latencies.append(time.monotonic() - pressed)  # reported, never asserted (a loaded machine)

    def navigate(self) -> None:
        window = self.gui.window
        self._goal = (self._goal + 1) % len(GOALS)
        window.controller.ask(GotoGoal(GOALS[self._goal]))
        pump(lambda: self.mode() == "Goto", 10, "the robot to navigate")
        pump(lambda: window.model.navigation.value.navigating, 5, "the window to see the navigation")

    def hold_dpad(self) -> tuple[int, int]:
        """Press (and keep pressed) the D-pad's forward arrow with the mouse; returns where."""
        window = self.gui.window
        if not window.dpad.get_visible():
            window.activate_action("win.dpad", None)
        pad = window.dpad.pads["drive_forward"]
        x, y = self.gui.centre_on_surface(pad)
        # The pointer may have rested on the pad since the last cycle: its tooltip ("Drive forward
        # (hold)") is then a window of its own over the pad and would take the press. Away first.
        self.gui.xdotool("mousemove", "--window", str(self.gui.xid()), "1", "1")
        idle(0.3)
        self.gui.xdotool("mousemove", "--window", str(self.gui.xid()), str(x), str(y), "mousedown", "1")
        return x, y

    def prove(self, what: str, *, dpad_here: bool = True) -> None:
        """After ``what`` (a pick, a page, a field with the focus): the whole cycle."""
        gui, window = self.gui, self.gui.window
        self.navigate()
        self.space_stops(f"navigating after {what}")
        pump(lambda: self.mode() == "stop", 5, "the simulator's stop mode")
        if dpad_here and window.dpad.get_mapped() and not owned_windows(window):
            self._dpad_then_space(what)
            back_to_map(gui)
        else:
            back_to_map(gui)
            self._dpad_then_space(f"{what}, back on the map")
        gui.keydown("Up")
        try:
            pump(self.driven, 8, f"a held Up to drive again after {what}")
        finally:
            gui.keyup("Up")
        pump(lambda: not self.driven(), 5, "the release to stop the robot")
        self.proved.append(what)

    def _dpad_then_space(self, what: str) -> None:
        gui = self.gui
        self.hold_dpad()
        try:
            pump(self.driven, 8, f"the D-pad to drive ({what})")
            self.space_stops(f"during a held D-pad drive ({what})")
            pump(lambda: not self.driven(), 5, "the held D-pad drive to end on Space")
        finally:
            gui.xdotool("mouseup", "1")


def back_to_map(gui: Gui) -> None:
    """Close what a pick opened (dialogs, popovers, panels, pick modes) and give the window the keys."""
    window = gui.window
    for other in owned_windows(window):
        other.close()
    pump(lambda: not owned_windows(window), 5, "the dialogs to close")
    for widget in descendants(window):
        if isinstance(widget, Gtk.Popover) and widget.get_mapped():
            widget.popdown()
    window.layers.close()
    window.picker.cancel()
    if window.stack.get_visible_child_name() != "map":
        window.show_map()
    gui.focus()
    idle(0.1)

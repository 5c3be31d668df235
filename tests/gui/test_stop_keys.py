"""Space stops the robot from every state of the window (issue 21), with real X input.

The menu is read from its model, so an item added later is picked here without editing this file;
each item is picked with the mouse and, in a second test, with the keyboard (F10, arrows, Return),
and each pick is followed by the whole proof (``stop_paths.StopCycle``): Space stops a navigation,
Space stops a D-pad drive held with the mouse, and a held Up drives again. One window serves every
item of a test, put back on the map between items (its toggles set back as they were).
"""

from __future__ import annotations

import gi

from rtmu.sim import SimThread
from simulators import simulator

from .harness import OFFICE_MAP, Gui, idle, pump
from .stop_paths import MenuEntry, MenuPicker, StopCycle, back_to_map, menu_entries, owned_windows

gi.require_version("Gtk", "4.0")
from gi.repository import Gio, Gtk  # noqa: E402

LEAVES_THE_WINDOW = {"app.quit"}
"""Ends the window: its own test (the robot is stopped before the app quits)."""


sim = simulator(map_path=OFFICE_MAP, seed=1)


def entries(gui: Gui) -> list[MenuEntry]:
    found = [e for e in menu_entries(gui.window.menu_model) if e.action not in LEAVES_THE_WINDOW]
    assert len(found) >= 20, [e.name for e in found]  # the robot's commands, Server, View, help, About
    return found


def toggles(window: Gtk.Window) -> dict[str, bool]:
    """Every boolean window action's state now (a pick flips one; it is set back after the proof)."""
    out = {}
    for name in window.list_actions():
        action = window.lookup_action(name)
        state = action.get_state() if isinstance(action, Gio.SimpleAction) else None
        if state is not None and state.get_type_string() == "b":
            out[name] = state.get_boolean()
    return out


def set_back(window: Gtk.Window, before: dict[str, bool]) -> None:
    for name, was in before.items():
        action = window.lookup_action(name)
        if action.get_state().get_boolean() != was and action.get_enabled():
            action.activate(None)
    if window.is_fullscreen():
        window.leave_fullscreen()


def pick_each(gui: Gui, sim: SimThread, how: str) -> list[str]:
    window, picker, cycle = gui.window, MenuPicker(gui), StopCycle(gui, sim)
    initial = toggles(window)
    for entry in entries(gui):
        (picker.by_mouse if how == "mouse" else picker.by_keyboard)(entry)
        pump(lambda: not picker.popover.get_mapped(), 3, f"the menu to close after {entry.name}")
        idle(0.3)  # what the pick opens (a dialog, a page) comes up
        if entry.action in (
            "win.about",
            "win.show-keys",
            "win.settings",
            "win.server-config",
            "win.files",
            "win.scan",
            "win.map-edit",
        ):
            pump(lambda: owned_windows(window), 5, f"{entry.name} to open its window")
        if len(cycle.proved) in (3, 12):
            gui.screen_shot(f"after-{how}-pick-{len(cycle.proved)}")
        cycle.prove(f"{how} pick of {entry.name}")
        back_to_map(gui)
        set_back(window, initial)
    lat = sorted(cycle.latencies)
    median, worst = lat[len(lat) // 2] * 1000, lat[-1] * 1000
    print(f"\n{how}: {len(lat)} stops, Space → simulator: median {median:.0f} ms, max {worst:.0f} ms")
    return cycle.proved


def test_every_menu_item_picked_with_the_mouse_then_space_stops_and_up_drives(
    gui: Gui, sim: SimThread
) -> None:
    proved = pick_each(gui, sim, "mouse")
    assert proved == [f"mouse pick of {e.name}" for e in entries(gui)]
    assert gui.window.key_reach.repairs >= 1, "a submenu pick strands the focus in GTK 4.8: it was put back"
    gui.shot("after-every-mouse-pick")


def test_every_menu_item_picked_with_the_keyboard_then_space_stops_and_up_drives(
    gui: Gui, sim: SimThread
) -> None:
    proved = pick_each(gui, sim, "keyboard")
    assert proved == [f"keyboard pick of {e.name}" for e in entries(gui)]
    gui.shot("after-every-keyboard-pick")

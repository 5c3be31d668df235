"""Everything by keyboard, with real key events (issue 21): Tab moves a visible focus through the bars,
Space on a focused button stops the robot and never clicks the button, F10 / Menu / Shift+F10 open the
menu, Ctrl+G the Go-to panel, a pick mode takes arrows and Return, and the keys window opens with
STOP and driving first, filters as the operator types and closes on Escape. (Every menu item by
keyboard: test_stop_keys; every Go-to item by keyboard: test_stop_keys_states; Alt+1…9 in a fleet:
test_stop_keys_states.)"""

from __future__ import annotations

import math

import gi
import pytest

from rtmu.model.observables import Phase
from rtmu.sim import SimThread
from rtmu.ui.keys_window import Heading, KeysWindow
from rtmu.ui.stop_keys import descendants
from simulators import simulator

from .harness import OFFICE_MAP, Gui, idle, pump
from .stop_paths import StopCycle, back_to_map, owned_windows
from .test_stop_keys_states import focus_until

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

sim = simulator(map_path=OFFICE_MAP, seed=1)


def test_tab_shows_the_focus_and_space_on_a_focused_button_stops_without_clicking_it(
    gui: Gui, sim: SimThread
) -> None:
    window, cycle = gui.window, StopCycle(gui, sim)
    assert window.get_focus() is None, "the window starts with no focused button: Return does nothing"
    gui.key("Tab")
    pump(lambda: window.get_focus() is not None, 3, "the first Tab")
    assert window.get_focus().is_ancestor(window.stop_button) or window.get_focus() is window.stop_button
    seen: list[Gtk.Widget] = []
    for _ in range(12):
        gui.key("Tab")
        idle(0.05)
        focus = window.get_focus()
        assert focus is not None and window.get_focus_visible(), "Tab shows where the focus is"
        seen.append(focus)
    for button in (window.stop_button, window.connect_button, window.menu_button, window.camera_button):
        assert any(f is button or f.is_ancestor(button) for f in seen), f"Tab never reached {button!r}"
    focus_until(gui, window.connect_button)  # "Disconnect": the button Space must never click
    gui.shot("disconnect-focused")
    cycle.navigate()
    cycle.space_stops("with the Disconnect button focused")
    idle(0.5)
    assert gui.phase is Phase.CONNECTED, "Space clicked the focused Disconnect button"
    focus_until(gui, window.stop_button)
    cycle.navigate()
    gui.key("Return")  # Return activates the focused button: here STOP
    pump(lambda: cycle.mode() == "stop", 3, "Return on the focused STOP to stop")


@pytest.mark.parametrize("key", ["F10", "Menu", "shift+F10"])
def test_f10_menu_and_shift_f10_open_the_menu(gui: Gui, key: str) -> None:
    popover = gui.window.menu_button.get_popover()
    assert popover is not None
    gui.key(key)
    pump(popover.get_mapped, 3, f"{key} to open the menu")
    gui.screen_shot(f"menu-by-{key}")
    gui.key("Escape")
    pump(lambda: not popover.get_mapped(), 3, "Escape to close it")


def test_the_menu_shows_the_keys_of_t_g_and_ctrl_k(gui: Gui) -> None:
    menu = gui.window.robot_menu
    accels = {}
    for i in range(menu.get_n_items()):
        action = menu.get_item_attribute_value(i, "action", None).get_string()
        accel = menu.get_item_attribute_value(i, "accel", None)
        accels[action] = accel.get_string() if accel is not None else ""
    assert (
        accels["win.turn"] == "t"
        and accels["win.go"] == "g"
        and accels["win.server-commands"] == "<Control>k"
    )
    gui.key("F10")
    popover = gui.window.menu_button.get_popover()
    pump(popover.get_mapped, 3, "the menu")
    gui.screen_shot("menu-with-keys")
    gui.key("Escape")


def test_go_to_point_and_set_position_by_keyboard_alone(gui: Gui, sim: SimThread) -> None:
    window, cycle = gui.window, StopCycle(gui, sim)
    panel = window.goals_panel
    for label, kind in (("Set position…", "localize"), ("Go to point…", "goto")):
        gui.key("ctrl+g")
        pump(lambda: panel.get_popover().get_mapped(), 3, "Ctrl+G to open the Go-to panel")
        focus_until(gui, panel.buttons[kind])
        gui.key("Return")
        pump(lambda: window.picker.active, 3, f"{label} to start its map mode")
        start = gui.model.robot.value
        for key in ("Right", "Right", "Right", "Up", "Down"):  # along the corridor
            gui.key(key)
        gui.key("ctrl+Left")  # its heading: 15° to the left
        pump(lambda: window.picker.marker is not None, 3, "the point to move")
        marker = window.picker.marker
        assert marker is not None and marker.x > start.x + 200 and abs(marker.y - start.y) < 1, marker
        assert marker.th is not None and abs(marker.th - (start.th + 15.0)) < 1
        assert cycle.mode() != "ratioDrive", "the arrows moved the point: they did not drive"
        gui.shot(f"{kind}-picked-by-keyboard")
        gui.key("Return")
        pump(lambda: not window.picker.active, 3, "Return to confirm")
        if kind == "localize":
            x, y = marker.x, marker.y
            pump(
                lambda x=x, y=y: math.hypot(sim.snapshot().x - x, sim.snapshot().y - y) < 50,
                5,
                "the robot placed there",
            )
        else:
            pump(lambda: cycle.mode() == "Goto", 5, "the robot to go to the point")
            cycle.space_stops("going to a point chosen by keyboard")
    back_to_map(gui)


def test_the_keys_window_opens_by_keyboard_stop_first_filtered_as_typed_and_escape_empties_then_closes(
    gui: Gui,
) -> None:
    window = gui.window
    gui.key("ctrl+question")
    pump(lambda: owned_windows(window), 5, "the keys window")
    keys = owned_windows(window)[0]
    assert isinstance(keys, KeysWindow)
    pump(lambda: in_search(keys), 3, "the search to have the keys")
    pump(keys.is_active, 5, "the X server to give the keys window the keyboard")  # before typing
    headings = [w.group for w in descendants(keys.rows) if isinstance(w, Heading) and w.get_mapped()]
    assert headings[:2] == ["STOP", "Driving"], f"the list starts with {headings}"
    first = next(line for line in keys.lines if line.get_mapped())
    assert first.row.title == "Stop" and first.row.accels == ("space", "KP_5", "<Control>space")
    gui.screen_shot("keys-first")
    gui.xdotool("type", "--delay", "30", "zoom")
    zooms = ["Zoom in", "Zoom out", "Zoom the camera in", "Zoom the camera out"]
    pump(lambda: [ln.row.title for ln in keys.lines if ln.get_mapped()] == zooms, 5, "typing to filter")
    headings = [w.group for w in descendants(keys.rows) if isinstance(w, Heading) and w.get_mapped()]
    assert headings == ["Map", "Camera head"], headings
    assert keys.note.get_mapped() and keys.note.get_text() == "4 of 40 keys"
    gui.screen_shot("keys-zoom")
    gui.xdotool("type", "--delay", "30", "qq")
    pump(lambda: not any(ln.get_mapped() for ln in keys.lines), 5, "no row for zoomqq")
    assert keys.note.get_text() == "No key matches “zoomqq”"
    gui.key("Escape")  # first it empties the search: the whole list again, the window stays
    pump(
        lambda: keys.search.get_text() == "" and all(ln.get_mapped() for ln in keys.lines),
        5,
        "Escape to empty the search",
    )
    assert keys.get_mapped() and not keys.note.get_mapped()
    gui.key("Escape")
    pump(lambda: not keys.get_mapped(), 5, "Escape to close the keys window")
    pump(window.is_active, 5, "the keyboard back on the window")
    gui.key("F1")
    pump(keys.get_mapped, 5, "F1 to open it again")
    assert keys.search.get_text() == "" and all(ln.get_child_visible() for ln in keys.lines), "starts whole"
    close = next(w for w in descendants(keys) if isinstance(w, Gtk.Button) and w.has_css_class("close"))
    gui.click(close)  # its title bar's close button (a phone has no Escape key)
    pump(lambda: not keys.get_mapped(), 5, "the close button to close the keys window")
    back_to_map(gui)


def in_search(keys: KeysWindow) -> bool:
    focus = keys.get_focus()
    return focus is not None and focus.is_ancestor(keys.search)

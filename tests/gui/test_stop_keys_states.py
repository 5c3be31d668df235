"""Space stops from the window's other states (issue 21): every popover and its items, text fields with
the focus, the camera page, split view, full screen, a phone-sized window, the fleet view; Escape and
Ctrl+K leave a navigation alone; keys that cannot reach the window are said, and drive nothing.

Real window, real simulator, real X input; the simulator's stop log says whether Space stopped.
"""

from __future__ import annotations

from pathlib import Path

import gi

from rtmu.control.key_rules import FIELD_HINT, KEYS_INACTIVE
from rtmu.settings.store import DirectRobot
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.multi import SimFleetThreads, fleet_configs
from rtmu.ui.options import GuiOptions
from rtmu.ui.stop_keys import descendants, is_guarded
from simulators import simulator

from .harness import OFFICE_MAP, Gui, idle, pump, scratch_dir, settle
from .stop_paths import StopCycle, back_to_map, menu_entries, owned_windows

gi.require_version("Gtk", "4.0")
gi.require_version("GdkX11", "4.0")
from gi.repository import GdkX11, Gtk  # noqa: E402

sim = simulator(map_path=OFFICE_MAP, seed=1)


def focus_until(gui: Gui, widget: Gtk.Widget, key: str = "Tab", limit: int = 60) -> None:
    """Press ``key`` (Tab) until ``widget`` (or a widget inside it) has the keyboard focus."""
    for _ in range(limit):
        focus = gui.window.get_focus()
        if focus is not None and (focus is widget or focus.is_ancestor(widget)):
            return
        gui.key(key)
        idle(0.02)
    raise AssertionError(f"{key} never reached {widget!r}")


def goals_popover(gui: Gui) -> Gtk.Popover:
    panel = gui.window.goals_panel
    pump(lambda: len(panel.rows) >= 5, 5, "the map's goals")
    popover = panel.get_popover()
    assert popover is not None
    return popover


def test_every_popover_carries_the_stop_keys_and_each_goals_item_is_followed_by_a_working_space(
    gui: Gui, sim: SimThread
) -> None:
    window, cycle = gui.window, StopCycle(gui, sim)
    popovers = [w for w in descendants(window) if isinstance(w, Gtk.Popover)]
    assert len(popovers) >= 4 and all(is_guarded(p) for p in popovers), "every popover has the stop keys"
    # Each popover open (its page shown first), Space while the robot navigates.
    window.show_camera()
    window.fullscreen_bar.set_reveal_child(True)
    opened = 0
    for popover in popovers:
        parent = popover.get_parent()
        if parent is None or not parent.get_mapped():
            continue  # a feature this server lacks (an LD robot's routes)
        cycle.navigate()
        popover.popup()
        pump(popover.get_mapped, 3, "the popover")
        cycle.space_stops(f"with the popover of {type(parent).__name__} open")
        popover.popdown()
        opened += 1
    window.fullscreen_bar.set_reveal_child(False)
    back_to_map(gui)
    assert opened >= 3, opened
    # The Go-to panel's items, picked with the mouse and with the keyboard (Ctrl+G, Tab, Return).
    panel = window.goals_panel
    popover = goals_popover(gui)
    items = [*panel.buttons.values(), panel.rows["Kitchen"]]
    for item in items:
        name = item.get_label() if isinstance(item, Gtk.Button) else "the goal Kitchen"
        gui.click(panel)
        pump(popover.get_mapped, 3, "the Go-to panel")
        gui.click(item)
        idle(0.3)
        cycle.prove(f"mouse pick of {name} in the Go-to panel")
        gui.key("ctrl+g")
        pump(popover.get_mapped, 3, "Ctrl+G to open the Go-to panel")
        focus_until(gui, item)
        gui.shot(f"goto-focus-{len(cycle.proved)}")
        gui.key("Return")
        idle(0.3)
        cycle.prove(f"keyboard pick of {name} in the Go-to panel")
    assert len(cycle.proved) == 2 * len(items)


def test_space_stops_in_text_fields_where_shift_space_types_and_the_field_says_so(
    gui: Gui, sim: SimThread
) -> None:
    window, cycle = gui.window, StopCycle(gui, sim)
    # The Go-to search (a popover of the window).
    popover = goals_popover(gui)
    gui.key("ctrl+g")
    pump(lambda: isinstance(window.get_focus(), Gtk.Text), 3, "the goal search to have the keys")
    search = window.goals_panel.search
    assert search.get_property("placeholder-text").endswith("· Space stops")
    assert FIELD_HINT in search.get_tooltip_text()
    gui.xdotool("type", "--delay", "30", "lab")
    gui.key("shift+space")
    pump(lambda: search.get_text() == "lab ", 3, "Shift+Space to type a space")
    gui.screen_shot("goal-search-typing")
    cycle.prove("typing in the Go-to search", dpad_here=False)
    assert not popover.get_mapped()
    # The server's commands (Ctrl+K: a dialog with its search field focused).
    gui.key("ctrl+k")
    pump(lambda: owned_windows(window), 5, "the palette")
    palette = owned_windows(window)[0]
    pump(lambda: isinstance(palette.get_focus(), Gtk.Text), 3, "the palette's search to have the keys")
    gui.xdotool("type", "--delay", "30", "wa")
    gui.key("shift+space")
    gui.xdotool("type", "--delay", "30", "x")
    pump(lambda: palette.search.get_text() == "wa x", 3, "typing with a Shift+Space")  # type: ignore[attr-defined]
    assert FIELD_HINT in palette.search.get_tooltip_text()  # type: ignore[attr-defined]
    gui.screen_shot("palette-typing")
    cycle.prove("typing in the palette's search")
    # The connection settings (its first text field has the focus).
    window.activate_action("win.settings", None)
    pump(lambda: owned_windows(window), 5, "the settings dialog")
    dialog = owned_windows(window)[0]
    pump(lambda: isinstance(dialog.get_focus(), Gtk.Text), 3, "a settings field to have the keys")
    gui.screen_shot("settings-field")
    cycle.prove("a settings field with the focus")
    # The server's configuration: an editor with the focus.
    window.activate_action("win.server-config", None)
    pump(lambda: owned_windows(window), 5, "the configuration page")
    page = owned_windows(window)[0]
    editors = lambda: [w for w in descendants(page) if isinstance(w, Gtk.Text) and w.get_mapped()]  # noqa: E731
    pump(lambda: bool(editors()), 10, "the configuration's editors")
    editors()[0].grab_focus()
    pump(lambda: isinstance(page.get_focus(), Gtk.Text), 3, "an editor to have the keys")
    gui.screen_shot("config-editor")
    cycle.prove("a configuration editor with the focus")


def test_space_stops_on_the_camera_page_in_split_view_full_screen_and_a_phone_sized_window(
    gui: Gui, sim: SimThread
) -> None:
    window, cycle = gui.window, StopCycle(gui, sim)
    gui.key("Escape")
    pump(lambda: window.stack.get_visible_child_name() == "camera", 3, "the camera page")
    cycle.prove("the camera page (Escape)", dpad_here=False)
    window.activate_action("win.split", None)
    pump(lambda: window.split.split, 3, "split view")
    gui.shot("split-view")
    cycle.prove("split view")
    window.activate_action("win.split", None)
    gui.key("F11")
    idle(0.5)  # without a window manager the server may ignore the request; the bar is revealed
    window.fullscreen_bar.set_reveal_child(True)
    settle(window)  # GDK emulates full screen by a resize the X server does later: aim after it
    gui.focus()  # and may take the focus with it: an operator's click gives it back (a WM would)
    cycle.prove("full screen (F11)")
    window.leave_fullscreen()
    window.fullscreen_bar.set_reveal_child(False)
    window.set_default_size(360, 720)
    pump(lambda: window.handheld.layout.narrow, 5, "the phone layout")
    settle(window)
    gui.shot("phone-sized")
    cycle.prove("a phone-sized window")
    window.set_default_size(800, 480)
    pump(lambda: not window.handheld.layout.narrow, 5, "the wide layout again")


def test_escape_and_ctrl_k_leave_a_navigation_alone(gui: Gui, sim: SimThread) -> None:
    window, cycle = gui.window, StopCycle(gui, sim)
    cycle.navigate()
    stops = cycle.stops()
    lease_events: list[str] = []
    for key, what in (("Escape", "the camera page"), ("Escape", "the map"), ("ctrl+k", "the palette")):
        gui.key(key)
        idle(0.6)
        snap = sim.snapshot()
        moving = abs(snap.vel) > 50 or abs(snap.rot_vel) > 5
        assert snap.mode_name == "Goto" and moving, f"{key} ({what}) stopped the navigation"
        assert cycle.stops() == stops, f"{key} sent a stop"
        assert window.model.navigation.value.navigating
        lease_events.append(what)
    gui.screen_shot("palette-while-navigating")
    pump(lambda: owned_windows(window), 3, "the palette")
    owned_windows(window)[0].close()
    gui.focus()
    idle(0.5)
    assert cycle.mode() == "Goto" and cycle.stops() == stops
    gui.key("space")
    pump(lambda: cycle.stops() > stops, 3, "Space to stop it")
    gui.shot("space-stopped")


def test_keys_that_cannot_reach_the_window_are_said_and_drive_nothing(gui: Gui, sim: SimThread) -> None:
    window, cycle = gui.window, StopCycle(gui, sim)
    window.activate_action("win.dpad", None)
    other = Gtk.Window(title="elsewhere")
    other.present()
    try:
        pump(other.get_mapped, 3, "the other window")
        gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(other.get_surface())))
        pump(lambda: not window.is_active(), 3, "the window to lose the keyboard")
        pump(lambda: window.banners.text("keys") == KEYS_INACTIVE, 3, "the keys banner")
        gui.shot("keys-inactive")
        cycle.hold_dpad()
        try:
            idle(0.8)
            assert not cycle.driven(), "a D-pad drive while Space cannot reach the window"
            said = " ".join(window.banners.text(t) or "" for t in window.banners.topics())
            assert "Not driving: Space could not stop it" in said, said
        finally:
            gui.xdotool("mouseup", "1")
    finally:
        other.destroy()
    gui.focus()
    pump(lambda: window.banners.text("keys") is None, 3, "the keys banner to go")
    # One of the window's own dialogs has the keys: the note says so, and Space still stops there.
    gui.key("g")
    pump(lambda: owned_windows(window), 3, "the Go dialog")
    pump(lambda: "Go a distance" in (window.banners.text("keys") or ""), 3, "the banner to name the dialog")
    gui.screen_shot("keys-in-the-go-dialog")
    cycle.prove("the Go dialog holding the keys")


def test_in_the_fleet_view_space_stops_the_selected_robot_and_alt_keys_pick_robots(screenshots: Path) -> None:
    with SimFleetThreads(fleet_configs(SimConfig(port=0, map_path=OFFICE_MAP), 2)) as fleet_sims:
        sims = fleet_sims.sims
        robots = tuple(DirectRobot(f"robot{i + 1}", "127.0.0.1", s.port) for i, s in enumerate(sims))
        options = GuiOptions(
            fleet=robots, settings_path=scratch_dir("settings-") / "settings.toml", persist=False
        )
        gui = Gui.open(options, screenshots, "fleet-stop-keys")
        try:
            fleet = gui.app.fleet
            pump(lambda: len(fleet) == 2, 10, "two robot sessions")
            pump(lambda: all(s.state.map.value.state == "ready" for s in fleet), 20, "every robot's map")
            for number, sim in ((2, sims[1]), (1, sims[0])):
                gui.key(f"alt+{number}")
                pump(lambda n=number: fleet.selected.value is fleet.sessions.value[n - 1], 3, f"Alt+{number}")
                cycle = StopCycle(gui, sim)
                cycle.prove(f"the fleet view, robot {number} selected by Alt+{number}")
            gui.key("alt+Next")
            pump(lambda: fleet.selected.value is fleet.sessions.value[1], 3, "Alt+Page Down: the next robot")
            labels = [e.label for e in menu_entries(gui.window.menu_model)]
            assert "robot2" in labels and "Next robot" in labels, labels
            gui.shot("fleet-robot2-selected")
        finally:
            gui.close()


def test_space_and_the_keypad_5_stop_the_robot_while_the_keys_window_is_open(
    gui: Gui, sim: SimThread
) -> None:
    """Help ▸ Keyboard shortcuts is a dialog of the window: its search types with Shift+Space, Space stops
    there, the keypad's 5 stops from a row, and neither closes it nor types into the search."""
    from rtmu.ui.keys_window import KeyLine, KeysWindow

    window, cycle = gui.window, StopCycle(gui, sim)
    gui.key("ctrl+question")
    pump(lambda: owned_windows(window), 5, "the keys window")
    keys = owned_windows(window)[0]
    assert isinstance(keys, KeysWindow) and is_guarded(keys)
    pump(lambda: isinstance(keys.get_focus(), Gtk.Text), 3, "the search to have the keys")
    pump(keys.is_active, 5, "the X server to give the keys window the keyboard")  # before typing
    assert FIELD_HINT in keys.search.get_tooltip_text()
    gui.xdotool("type", "--delay", "30", "turn")
    gui.key("shift+space")
    pump(lambda: keys.search.get_text() == "turn ", 5, "Shift+Space to type a space")
    cycle.navigate()
    cycle.space_stops("with the keys window's search focused")
    assert keys.get_mapped() and keys.search.get_text() == "turn ", "Space stopped: it typed nothing"
    for _ in range(20):  # Tab to a row of the list
        if isinstance(keys.get_focus(), KeyLine):
            break
        gui.key("Tab")
        idle(0.05)
    assert isinstance(keys.get_focus(), KeyLine), keys.get_focus()
    gui.screen_shot("keys-window-row-focused")
    cycle.navigate()
    before = cycle.stops()
    gui.key("KP_5")
    pump(lambda: cycle.stops() > before, 5, "the keypad's 5 to stop the robot from a row")
    assert keys.get_mapped()
    # Not modal: the window's STOP button takes a click while the keys window is open (moved off it:
    # no window manager here places it).
    gui.xdotool("windowmove", "--sync", str(GdkX11.X11Surface.get_xid(keys.get_surface())), "700", "300")
    cycle.navigate()
    before = cycle.stops()
    gui.click(window.stop_button)
    pump(lambda: cycle.stops() > before, 5, "a click on STOP with the keys window open")
    assert keys.get_mapped()
    gui.screen_shot("stop-clicked-beside-the-keys-window")
    cycle.prove("the keys window open")  # and the whole cycle: Space, the D-pad, a held Up after it

"""One table says key → action, and the real window has every action it names.

Every key of ``keys.bindings()`` reaches, through the window's own key router, the binding that
names it, and that binding's action exists on the window (``win.*``) or the application (``app.*``)
with the parameter it passes; the application's accelerators are the table's; the menu rows show
the table's keys and run actions that exist; the keys window lists every key of the table and no other.
Then a few keys go through the X server and their actions are seen to run, also while one is greyed.
"""

from __future__ import annotations

import gi

from rtmu.ui.keys import bindings, menu_accel
from simulators import simulator

from .harness import OFFICE_MAP, Gui, pump
from .stop_paths import menu_entries

gi.require_version("Gtk", "4.0")
from gi.repository import Gio, Gtk  # noqa: E402

sim = simulator(map_path=OFFICE_MAP, seed=1)


def action_of(gui: Gui, detailed: str) -> Gio.Action | None:
    _ok, name, _target = Gio.Action.parse_detailed_name(detailed)
    group, _, short = name.partition(".")
    owner = gui.window if group == "win" else gui.app
    return owner.lookup_action(short)


def test_every_key_reaches_an_action_the_window_has(gui: Gui) -> None:
    window, router = gui.window, gui.window.keys
    for b in bindings():
        if b.held:
            continue
        action = action_of(gui, b.action)
        assert action is not None, f"{b.title}: no action {b.action}"
        _ok, _name, target = Gio.Action.parse_detailed_name(b.action)
        wanted = action.get_parameter_type()
        assert (target is None) == (wanted is None), f"{b.action}: parameter"
        if b.accelerator:  # GTK's accelerators carry it: the app holds exactly the table's keys
            assert sorted(gui.app.get_accels_for_action(b.action)) == sorted(b.accels), b.action
            continue
        for accel in b.accels:
            ok, keyval, mods = Gtk.accelerator_parse(accel)
            assert ok and router.lookup(keyval, mods) == b, f"{accel} does not reach {b.title}"
    assert window.actions.activate("win.no-such-action") is False
    gui.shot("action-table")


def test_the_menu_and_the_keys_window_read_the_table(gui: Gui) -> None:
    window = gui.window
    model = window.menu_model
    rows = list(menu_entries(model))
    assert len(rows) >= 20
    for row in rows:
        detailed = row.action if row.target is None else f"{row.action}({row.target.print_(False)})"
        assert action_of(gui, detailed) is not None, f"menu row {row.name}: no action {detailed}"
    accels: dict[str, str | None] = {}
    stack: list[Gio.MenuModel] = [model]
    while stack:
        menu = stack.pop()
        for i in range(menu.get_n_items()):
            for link in ("section", "submenu"):
                if (child := menu.get_item_link(i, link)) is not None:
                    stack.append(child)
            action = menu.get_item_attribute_value(i, "action", None)
            if action is None:
                continue
            target = menu.get_item_attribute_value(i, "target", None)
            detailed = action.get_string() + ("" if target is None else f"({target.print_(False)})")
            accel = menu.get_item_attribute_value(i, "accel", None)
            accels[detailed] = None if accel is None else accel.get_string()
    for detailed, accel in accels.items():
        assert accel == menu_accel(detailed), f"{detailed}: the menu shows {accel}, the table another"
    assert accels["win.turn"] == "t" and accels["win.settings"] == "<Control>comma"
    keys = window.keys_help.present()
    pump(keys.get_mapped, 5, "the keys window")
    listed = [a for line in keys.shown_lines() for a in line.row.accels]
    assert sorted(listed) == sorted(a for b in bindings() for a in b.accels), "listed ≠ bound"
    titles = {line.row.title for line in keys.shown_lines()}
    assert titles == {b.title for b in bindings()}, "a binding without its row"
    keys.close()
    pump(lambda: not keys.get_mapped(), 5, "the keys window to close")
    gui.shot("menu-reads-the-table")


def test_keys_run_their_actions_and_a_greyed_one_says_why(gui: Gui) -> None:
    window, stage = gui.window, gui.stage
    following = stage.follow
    gui.key("f")  # win.follow: the map and the follow button's check move together
    pump(lambda: stage.follow != following, 3, "F to turn following over")
    assert window.follow_button.get_active() == stage.follow
    assert window.actions.follow_action.get_state().get_boolean() == stage.follow
    window.follow_button.activate()  # the button runs the same action
    pump(lambda: stage.follow == following, 3, "the follow button to turn it back")
    zoom = stage.viewport.zoom
    gui.key("ctrl+plus")
    pump(lambda: stage.viewport.zoom > zoom, 3, "Ctrl+plus to zoom in")
    gui.key("ctrl+d")  # disconnect: the commands grey out …
    pump(lambda: not window.lookup_action("turn").get_enabled(), 5, "Turn to be greyed")
    gui.key("t")  # … and their keys still answer, with the reason
    pump(lambda: window.banners.text("notice:turn") is not None, 3, "the reason banner")
    assert "not connected" in window.banners.text("notice:turn")  # type: ignore[operator]
    gui.shot("greyed-key-says-why")

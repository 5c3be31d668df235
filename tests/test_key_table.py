"""The one key table (``ui.keys``): every key names an action or a held drive, and the menu and the
application's accelerators read it — checked without a display (the window's own check, that each
action exists, is ``tests/gui/test_action_table.py``)."""

from __future__ import annotations

import gi

from rtmu.control.commands import COMMANDS, action_name
from rtmu.ui.keys import WINDOW_BINDINGS, accelerated, bindings, menu_accel, menu_item

gi.require_version("Gio", "2.0")
from gi.repository import Gio  # noqa: E402


def test_every_key_does_one_thing_named_in_the_table() -> None:
    for b in bindings():
        assert bool(b.action) != bool(b.held), f"{b.title}: an action or a held drive, not both"
        if b.held:
            assert COMMANDS.get(b.held).hold, f"{b.title}: {b.held} is not a held command"
            continue
        ok, name, _target = Gio.Action.parse_detailed_name(b.action)
        assert ok and name.startswith(("win.", "app.")), b.action


def test_a_commands_keys_activate_its_action_and_a_held_commands_keys_drive() -> None:
    table = bindings()
    for c in COMMANDS:
        if not c.keys:
            continue
        found = [b for b in table if b.accels == c.keys and b.title == c.label]
        assert len(found) == 1, c.name
        assert (found[0].held, found[0].action) == (
            (c.name, "") if c.hold else ("", f"win.{action_name(c.name)}")
        )


def test_the_window_keys_name_window_actions_and_only_the_app_keys_are_accelerators() -> None:
    names = [b.action for b in WINDOW_BINDINGS]
    assert len(names) == len(set(names)), "one binding per action"
    assert {b.action for b in accelerated()} == {
        "win.fullscreen", "win.toolbar", "win.settings", "win.show-keys", "app.quit",
    }  # fmt: skip
    assert not any(b.held for b in WINDOW_BINDINGS), "held drive keys are the registry's"


def test_the_menu_shows_the_tables_key() -> None:
    assert menu_accel("win.select-robot(3)") == "<Alt>3"
    assert menu_accel("win.turn") == COMMANDS.get("turn").keys[0]
    assert menu_accel("app.quit") == "<Control>q"
    assert menu_accel("win.about") is None, "no key: the row shows none"
    model = Gio.Menu()
    model.append_item(menu_item("robot2", "win.select-robot(2)"))
    model.append_item(menu_item("About RTMU", "win.about"))
    assert model.get_item_attribute_value(0, "action", None).get_string() == "win.select-robot"
    assert model.get_item_attribute_value(0, "target", None).get_int32() == 2
    assert model.get_item_attribute_value(0, "accel", None).get_string() == "<Alt>2"
    assert model.get_item_attribute_value(1, "accel", None) is None

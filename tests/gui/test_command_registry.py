"""One definition per command: a command class added to the registry — and nothing else — shows up
in the real window as an action, a key, a robot-menu row and a row of the keys window."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import ClassVar

import pytest

from rtmu.control.commands import COMMANDS, Command, CommandTarget
from rtmu.ui.keys import bindings
from rtmu.ui.keys_sheet import KeySheet
from simulators import running

from .harness import OFFICE_MAP, Gui, pump


class Wave(Command):
    """A test-only command: records that it ran."""

    name = "test_wave"
    label = "Wave the flag"
    keys = ("<Control>j",)
    group = "Moves"
    menu = True
    needs = ("ratioDrive",)
    ran: ClassVar[list[CommandTarget]] = []

    def activate(self, target: CommandTarget) -> None:
        Wave.ran.append(target)


@pytest.fixture
def gui(screenshots: Path) -> Iterator[Gui]:
    COMMANDS.register(Wave)
    Wave.ran.clear()
    try:
        with running(map_path=OFFICE_MAP, seed=1) as sim:
            gui = Gui.start(screenshots, "command-registry", "127.0.0.1", sim.port)
            try:
                yield gui
            finally:
                gui.close()
    finally:
        COMMANDS.unregister(Wave.name)


def robot_menu_labels(gui: Gui) -> dict[str, str]:
    menu = gui.window.robot_menu
    return {
        menu.get_item_attribute_value(i, "action", None).get_string(): menu.get_item_attribute_value(
            i, "label", None
        ).get_string()
        for i in range(menu.get_n_items())
    }


def test_a_new_command_class_is_an_action_a_key_a_menu_row_and_a_shortcut(gui: Gui) -> None:
    window = gui.window
    action = window.lookup_action("test-wave")
    assert action is not None, "no win.test-wave action"
    assert action.get_enabled(), "enabled: the simulator offers ratioDrive"
    assert robot_menu_labels(gui).get("win.test-wave") == "Wave the flag"
    assert "Wave the flag" in [r.title for r in KeySheet.of(bindings()).rows]
    gui.shot("registry-command")

    gui.key("ctrl+j")  # a real key press through the X server
    pump(lambda: len(Wave.ran) == 1, 3, "the key to run the command")
    assert Wave.ran[0] is window.controller

    window.activate_action("win.test-wave", None)  # what the menu row does
    pump(lambda: len(Wave.ran) == 2, 3, "the action to run the command")

    gui.key("ctrl+d")  # disconnected: greyed with its reason, and the key no longer runs it
    pump(lambda: not action.get_enabled(), 3, "the command to be disabled")
    assert robot_menu_labels(gui)["win.test-wave"] == "Wave the flag — not connected"
    gui.key("ctrl+j")
    pump(lambda: window.banners.text("notice:test_wave") is not None, 3, "the reason banner")
    assert len(Wave.ran) == 2

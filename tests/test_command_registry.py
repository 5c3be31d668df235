"""The registry is the only table of commands: names and keys are unique, and the window's own keys
(zoom, follow, camera page, application actions) never take a key a command has."""

from __future__ import annotations

import pytest

from rtmu.control.commands import COMMANDS, Command, CommandRegistry, CommandTarget, action_name


def test_names_keys_and_actions_are_unique() -> None:
    names = [c.name for c in COMMANDS]
    assert len(names) == len(set(names))
    actions = [action_name(n) for n in names]
    assert len(actions) == len(set(actions))
    keys = [k for c in COMMANDS for k in c.keys]
    assert len(keys) == len(set(keys)), keys
    for c in COMMANDS:
        assert c.label and c.group, c.name


def test_a_second_command_on_a_taken_key_is_refused() -> None:
    registry = CommandRegistry()

    class One(Command):
        name = "one"
        label = "One"
        keys = ("x",)

        def activate(self, target: CommandTarget) -> None:
            pass

    class Two(One):
        name = "two"

    registry.register(One)
    with pytest.raises(ValueError, match="already runs 'one'"):
        registry.register(Two)
    with pytest.raises(ValueError, match="two commands named"):
        registry.register(One)


def test_the_window_keys_take_no_command_key() -> None:
    from rtmu.ui.keys import WINDOW_BINDINGS

    command_keys = COMMANDS.keys()
    for binding in WINDOW_BINDINGS:
        for key in binding.accels:
            assert key not in command_keys, f"{key} is both {binding.title!r} and {command_keys[key]!r}"
        name = binding.action.removeprefix("win.").replace("-", "_")
        assert name not in COMMANDS, f"{binding.action} runs a command: define it once, in the registry"


def test_no_dead_commands() -> None:
    """Every command does something: it overrides activate (the base raises)."""
    for c in COMMANDS:
        assert type(c).activate is not Command.activate, c.name

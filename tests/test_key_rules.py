"""Where the keyboard is, Space stops: the stop-key rule every surface of the window applies (GTK-free)."""

from __future__ import annotations

import pytest

from rtmu.control.key_rules import (
    FIELD_HINT,
    KEYS_INACTIVE,
    KeyAction,
    keys_note,
    stop_key_action,
    stop_key_names,
)


def test_the_stop_keys_come_from_the_registry() -> None:
    assert stop_key_names() == frozenset({"space", "KP_5"})


@pytest.mark.parametrize("in_text", [False, True])
def test_space_stops_everywhere_even_in_a_text_field(in_text: bool) -> None:
    assert stop_key_action("space", in_text=in_text) is KeyAction.STOP
    assert stop_key_action("space", ctrl=True, in_text=in_text) is KeyAction.STOP


def test_shift_space_types_a_space_in_a_text_field_and_stops_elsewhere() -> None:
    assert stop_key_action("space", shift=True, in_text=True) is KeyAction.TYPE
    assert stop_key_action("space", shift=True, in_text=False) is KeyAction.STOP
    assert "Shift+Space types a space" in FIELD_HINT and "Space stops the robot" in FIELD_HINT


def test_the_keypad_five_types_its_digit_in_a_field_and_stops_elsewhere() -> None:
    assert stop_key_action("KP_5", in_text=True) is KeyAction.TYPE
    assert stop_key_action("KP_5") is KeyAction.STOP
    assert stop_key_action("KP_5", ctrl=True, in_text=True) is KeyAction.STOP


def test_other_keys_and_alt_space_are_not_stop_keys() -> None:
    assert stop_key_action("Up") is KeyAction.PASS
    assert stop_key_action("Return", in_text=True) is KeyAction.PASS
    assert stop_key_action("space", alt=True) is KeyAction.PASS  # the window manager's window menu


def test_the_keys_note_says_where_the_keys_went() -> None:
    assert keys_note(window_active=True, connected=True) == ""
    assert keys_note(window_active=False, connected=False) == ""  # nothing to drive
    assert keys_note(window_active=False, connected=True) == KEYS_INACTIVE
    note = keys_note(window_active=False, connected=True, dialog="Go a distance")
    assert "Go a distance" in note and "Space stops the robot there" in note

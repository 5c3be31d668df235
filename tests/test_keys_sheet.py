"""The keys window's rows (``ui.keys_sheet``), without a display: made from the one key table, every key
it binds listed and none it does not, STOP first, key caps in words, a search that filters, German."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from rtmu.control.commands import COMMANDS
from rtmu.control.key_rules import KeyAction, stop_key_action
from rtmu.ui.keys import KeyRouter, bindings
from rtmu.ui.keys_sheet import GROUP_ORDER, KeySheet, count_note, key_caps


@dataclass(frozen=True)
class Entry:
    accels: tuple[str, ...]
    title: str
    group: str


def test_the_sheet_lists_every_key_the_window_binds_and_no_other() -> None:
    sheet = KeySheet.of(bindings())
    bound = {a for b in bindings() for a in b.accels}
    assert sheet.accels() == bound
    listed = [a for r in sheet.rows for a in r.accels]
    assert len(listed) == len(set(listed)), "a key listed twice"
    # Every listed key reaches the binding the row names (the router the window uses, no display needed).
    import gi

    gi.require_version("Gtk", "4.0")
    from gi.repository import Gtk

    router = KeyRouter(hold=print, release=print, activate=print)
    for row in sheet.rows:
        for accel in row.accels:
            binding = next(b for b in bindings() if accel in b.accels)
            assert row.title == binding.title and row.group == binding.group
            if not binding.accelerator:
                ok, keyval, mods = Gtk.accelerator_parse(accel)
                assert ok and router.lookup(keyval, mods) == binding, accel


def test_a_key_added_to_the_registry_appears_and_leaves_with_it() -> None:
    from rtmu.control.commands import Command, command

    @command
    class Wave(Command):
        name = "test_sheet_wave"
        label = "Wave the flag"
        keys = ("<Control><Shift>j",)
        group = "Robot"

        def activate(self, target: object) -> None:  # type: ignore[override]
            pass

    try:
        row = next(r for r in KeySheet.of(bindings()).rows if r.title == "Wave the flag")
        assert row.chords == (("Ctrl", "Shift", "J"),) and row.group == "Robot"
    finally:
        COMMANDS.unregister("test_sheet_wave")
    assert not [r for r in KeySheet.of(bindings()).rows if r.title == "Wave the flag"]


def test_stop_comes_first_then_driving_and_groups_keep_their_order() -> None:
    sheet = KeySheet.of(bindings())
    assert sheet.groups[:2] == ("STOP", "Driving")
    stop = sheet.rows[0]
    assert stop.title == "Stop" and stop.chords == (("Space",), ("Keypad 5",), ("Ctrl", "Space"))
    ctrl_space = stop_key_action("space", ctrl=True, in_text=True)
    assert ctrl_space is KeyAction.STOP, "the sheet lists Ctrl+Space because the stop-key rule stops on it"
    known = [g for g in sheet.groups if g in GROUP_ORDER]
    assert known == sorted(known, key=GROUP_ORDER.index)
    rows = KeySheet.of([Entry(("x",), "Odd one", "Elsewhere"), Entry(("space",), "Stop", "STOP")]).rows
    assert [r.group for r in rows] == ["STOP", "Elsewhere"], "a group not in the order comes last"


def test_key_caps_say_each_key_in_words_or_signs() -> None:
    assert key_caps("<Control>plus") == ("Ctrl", "+")
    assert key_caps("<Shift>F10") == ("Shift", "F10")
    assert key_caps("<Alt>Page_Down") == ("Alt", "Page Down")
    assert key_caps("KP_Subtract") == ("Keypad -",)
    assert key_caps("Up") == ("↑",) and key_caps("w") == ("W",) and key_caps("question") == ("?",)
    for bad in ("<Control>", "<Hyper>x"):
        with pytest.raises(ValueError):
            key_caps(bad)


def test_robots_one_to_nine_are_one_row_drawn_as_a_run() -> None:
    row = next(r for r in KeySheet.of(bindings()).rows if r.accels[0] == "<Alt>1")
    assert row.accels == tuple(f"<Alt>{n}" for n in range(1, 10))
    assert row.through and row.chords == (("Alt", "1"), ("Alt", "9"))
    assert row.keys_words() == "Alt+1 … Alt+9"
    gap = KeySheet.of([Entry((f"<Alt>{n}",), "Pick", "Fleet") for n in (1, 2, 4)]).rows[0]
    assert not gap.through and len(gap.chords) == 3, "a run only when no key is missing from it"


def test_each_row_has_a_spoken_name_with_its_keys() -> None:
    sheet = KeySheet.of(bindings())
    zoom = next(r for r in sheet.rows if r.title == "Zoom in")
    assert zoom.spoken() == "Zoom in: Ctrl++ / Ctrl+= / Ctrl+Keypad +"
    assert all(r.spoken().startswith(r.title + ": ") and r.chords for r in sheet.rows)


def test_the_search_keeps_rows_whose_words_heading_or_keys_hold_every_word() -> None:
    sheet = KeySheet.of(bindings())
    assert sheet.matching("") == sheet.rows and sheet.matching("  ") == sheet.rows
    assert [r.title for r in sheet.matching("ZOOM camera")] == ["Zoom the camera in", "Zoom the camera out"]
    assert {r.title for r in sheet.matching("space")} == {"Stop"}
    assert {r.group for r in sheet.matching("fleet")} == {"Fleet"}
    ctrl = sheet.matching("ctrl")
    assert ctrl and all("Ctrl" in r.keys_words() for r in ctrl)
    assert sheet.matching("no such key at all") == ()
    accented = KeySheet.of([Entry(("z",), "Zóóm ïn", "Máp")])
    assert accented.matching("zoom in") == accented.rows, "accents and case do not matter"


def test_the_note_says_how_many_match_or_that_none_does() -> None:
    assert count_note(40, 40, "") == "" and count_note(40, 40, "a") == ""
    assert count_note(2, 40, "zoom") == "2 of 40 keys"
    assert count_note(0, 40, " xyz ") == "No key matches “xyz”"


def test_in_german_the_words_and_the_key_names_are_german(german: None) -> None:
    sheet = KeySheet.of(bindings())
    assert sheet.groups[:2] == ("STOPP", "Fahren")
    stop = sheet.rows[0]
    assert stop.chords == (("Leertaste",), ("Ziffernblock 5",), ("Strg", "Leertaste"))
    zoom = next(r for r in sheet.rows if r.accels[0] == "<Control>plus")
    assert zoom.chords[0] == ("Strg", "+") and zoom.title == "Vergrößern"
    assert key_caps("<Shift>Page_Up") == ("Umschalt", "Bild ↑")
    assert count_note(2, 40, "x") == "2 von 40 Tasten"

"""The configuration page's edit state (``ui.config_edits``), without a display or a server."""

from __future__ import annotations

from dataclasses import replace

from rtmu.client.config_feed import ConfigSection, ServerConfig
from rtmu.protocol.payloads.config import ConfigParam, ParamType, SetConfigReply
from rtmu.ui.config_edits import ConfigEdits, RowNote, unchanged
from rtmu.values.intents import SetConfig

TIMEOUT = ConfigParam("Timeout", ParamType.DOUBLE, 2.0, minimum=0.0, maximum=10.0, precision=2)
NAME = ConfigParam("Name", ParamType.STRING, "robot1")
SAFE = ConfigParam("SafeDrive", ParamType.BOOL, True)


def config(timeout: float = 2.0, name: str = "robot1") -> ServerConfig:
    return ServerConfig(
        (
            ConfigSection("Teleop", "", (replace(TIMEOUT, value=timeout), SAFE)),
            ConfigSection("Robot", "", (replace(NAME, value=name),)),
        )
    )


def loaded(timeout: float = 2.0) -> ConfigEdits:
    edits = ConfigEdits()
    edits.fetched(config(timeout))
    return edits


def test_an_editor_reshowing_the_value_is_not_an_edit() -> None:
    edits = loaded()
    assert unchanged(TIMEOUT, "2.00") and unchanged(TIMEOUT, "2")
    assert not edits.edit(("Teleop", "Timeout"), TIMEOUT, "2.00"), "a spin button formatting 2 as 2.00"
    assert edits.edits == {}
    assert edits.edit(("Teleop", "Timeout"), TIMEOUT, "0.50")
    assert not edits.edit(("Teleop", "Timeout"), TIMEOUT, "0.50"), "the same edit again"
    assert edits.edits == {("Teleop", "Timeout"): "0.50"}
    assert edits.note(("Teleop", "Timeout"), TIMEOUT) == RowNote("edited", "edited")
    assert edits.edit(("Teleop", "Timeout"), TIMEOUT, "2"), "typed back to the server's value: no edit left"
    assert edits.edits == {} and edits.note(("Teleop", "Timeout"), TIMEOUT) == RowNote()


def test_a_wrong_value_is_said_and_blocks_saving() -> None:
    edits = loaded()
    edits.edit(("Teleop", "Timeout"), TIMEOUT, "11")
    assert list(edits.invalid()) == [("Teleop", "Timeout")]
    note = edits.note(("Teleop", "Timeout"), TIMEOUT)
    assert note.style == "error" and note.text.startswith("✗ ")
    assert not edits.can_save(saving=False) and edits.save_intent() is None
    assert edits.status() == "3 parameters, 1 unsaved, 1 invalid"


def test_saving_builds_one_set_config_intent_from_every_edit() -> None:
    edits = loaded()
    edits.edit(("Teleop", "Timeout"), TIMEOUT, "0.50")
    edits.edit(("Robot", "Name"), NAME, "patrol bot")
    assert edits.can_save(saving=False) and not edits.can_save(saving=True)
    found = edits.save_intent()
    assert found is not None
    sent, intent = found
    assert intent == SetConfig({"Teleop": {"Timeout": "0.50"}, "Robot": {"Name": "patrol bot"}})
    assert sent == {("Teleop", "Timeout"): "0.50", ("Robot", "Name"): "patrol bot"}

    edits.edit(("Robot", "Name"), NAME, "patrol bot 2")  # typed again while the set was on its way
    assert edits.saved(sent, SetConfigReply("")) == ""
    assert edits.edits == {("Robot", "Name"): "patrol bot 2"}, "the newer edit is still to save"
    assert edits.answers[("Teleop", "Timeout")] == (True, "✓ accepted")


def test_a_refusal_names_its_parameter_or_the_whole_set() -> None:
    edits = loaded()
    edits.edit(("Teleop", "Timeout"), TIMEOUT, "0.05")
    edits.edit(("Robot", "Name"), NAME, "x")
    found = edits.save_intent()
    assert found is not None
    sent, _intent = found
    assert edits.saved(sent, SetConfigReply("Teleop/Timeout: below the minimum")) == ""
    assert edits.note(("Teleop", "Timeout"), TIMEOUT) == RowNote(
        "✗ Teleop/Timeout: below the minimum", "error"
    )
    assert edits.answers[("Robot", "Name")] == (False, "not saved: the server refused the set")
    assert edits.edits == sent, "a refused edit is kept, not lost"
    assert edits.saved(sent, SetConfigReply("busy")) == "The server refused: busy"
    edits.save_failed(sent, "the link was lost")
    assert edits.answers[("Robot", "Name")] == (False, "✗ not saved: the link was lost")


def test_another_clients_change_is_said_and_an_equal_edit_dropped() -> None:
    edits = loaded()
    edits.edit(("Teleop", "Timeout"), TIMEOUT, "3")
    edits.edit(("Robot", "Name"), NAME, "mine")
    old, new = config(), config(timeout=3.0, name="theirs")
    edits.fetched(new)
    assert edits.fetches == 2
    assert edits.edits == {("Robot", "Name"): "mine"}, "they set exactly my Timeout: nothing left to save"
    text = edits.changes_note(old, new)
    assert text.startswith("Another client changed Teleop/Timeout (now 3")
    assert "Robot/Name (now theirs)" in text
    assert "Your unsaved edit of Robot/Name is kept: Save would overwrite their value." in text
    assert edits.changes_note(new, new) == "Another client saved the configuration; no value changed."


def test_an_edit_of_a_parameter_the_server_dropped_is_invalid() -> None:
    edits = loaded()
    edits.edit(("Robot", "Name"), NAME, "x")
    edits.fetched(ServerConfig((ConfigSection("Teleop", "", (TIMEOUT,)),)))
    assert edits.invalid() == {("Robot", "Name"): "no longer offered by the server"}
    assert ConfigEdits().status() == "" and ConfigEdits().invalid() == {}


def test_a_value_out_of_its_limits_is_refused_in_words_not_clamped() -> None:
    """The spin button puts the held value back rather than clamp 99 to 10: the row says so (issue 21)."""
    edits, key = loaded(), ("Teleop", "Timeout")
    assert edits.edit(key, TIMEOUT, "99")
    assert edits.note(key, TIMEOUT) == RowNote("✗ above the maximum of 10", "error")
    assert edits.edit(key, TIMEOUT, ""), "a spin button empties itself before it shows a value"
    assert edits.edit(key, TIMEOUT, "2.00"), "the editor put the held value back"
    assert edits.edits == {}
    assert edits.note(key, TIMEOUT) == RowNote("✗ 99 not taken: above the maximum of 10 (still 2)", "error")
    assert edits.edit(key, TIMEOUT, "3.00")
    assert edits.note(key, TIMEOUT) == RowNote("edited", "edited"), "the next edit ends the refusal"


def test_an_accepted_answer_goes_when_another_client_changes_the_value() -> None:
    edits, key = loaded(), ("Teleop", "Timeout")
    edits.edit(key, TIMEOUT, "0.50")
    found = edits.save_intent()
    assert found is not None
    edits.saved(found[0], SetConfigReply(""))
    edits.fetched(config(0.5))
    assert edits.note(key, TIMEOUT) == RowNote("✓ accepted", "ok"), "the value it was for is held"
    edits.fetched(config(3.0))  # another client set 3
    assert edits.note(key, TIMEOUT) == RowNote(), "no tick beside a value nobody here set"


def test_a_separator_is_no_parameter() -> None:
    line = ConfigParam("", ParamType.SEPARATOR)
    both = ServerConfig((ConfigSection("Teleop", "", (TIMEOUT, line, SAFE)),))
    assert both.param_count == 2
    edits = ConfigEdits()
    edits.fetched(both)
    assert edits.status() == "2 parameters"

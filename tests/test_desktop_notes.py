"""What the window tells the desktop while it is away (``ui.desktop_notify``), and the settings that
switch each kind off."""

from __future__ import annotations

import pytest

from rtmu.model.observables import ConnectionState, NavState, Phase, PopupsState, RobotState
from rtmu.settings.notifications import NOTIFICATION_KINDS
from rtmu.settings.store import Settings, SettingsError, format_settings, parse_settings
from rtmu.ui.desktop_notify import battery_note, link_note, nav_note, popup_note
from rtmu.values.state import NavOutcome, PopupInfo


def test_arrived_failed_and_docked_are_said_once_each() -> None:
    going = NavState(navigating=True, target="Lab B")
    arrived = NavState(target="Lab B", outcome=NavOutcome.ARRIVED)
    note = nav_note(going, arrived, "R1")
    assert note is not None and (note.kind, note.title, note.body) == ("arrived", "R1 arrived", "At Lab B.")
    assert nav_note(arrived, arrived, "R1") is None
    failed = NavState(target="Lab B", outcome=NavOutcome.FAILED, outcome_text="Failed to get to Lab B\x1b[2J")
    said = nav_note(going, failed, "R1")
    assert said is not None and said.kind == "failed"
    assert said.body.startswith("The robot says: “") and "\x1b" not in said.body
    docked = nav_note(going, NavState(outcome=NavOutcome.DOCKED), "R1")
    assert docked is not None and docked.kind == "docked"
    assert nav_note(going, NavState(outcome=NavOutcome.CANCELLED), "R1") is None


def test_the_battery_is_said_when_it_falls_to_low_not_while_it_stays_there() -> None:
    levels = dict(battery_low=11.5, battery_shutdown=11.0)
    ok, low = RobotState(battery_v=12.0, **levels), RobotState(battery_v=11.4, **levels)
    note = battery_note(ok, low, "R1")
    assert note is not None and note.kind == "battery_low" and "11.4 V" in note.body
    assert battery_note(low, RobotState(battery_v=11.3, **levels), "R1") is None
    assert battery_note(RobotState(), low, "R1") is None  # the first reading: the window says it


def test_a_lost_link_is_said_but_the_operators_disconnect_is_not() -> None:
    up = ConnectionState(phase=Phase.CONNECTED)
    lost = link_note(up, ConnectionState(phase=Phase.RECONNECTING, error="no status for 2 s"), "R1")
    assert lost is not None and lost.kind == "link_lost" and "2 s" in lost.body
    assert link_note(up, ConnectionState(phase=Phase.DISCONNECTED), "R1") is None


def test_a_new_popup_is_said_with_its_title_as_the_robots_words() -> None:
    first = PopupInfo(1, "Door", "Open it?", 4, ("Yes", "No", ""))
    second = PopupInfo(2, "Lift", "", 1, ("OK", "", ""))
    one = PopupsState(open=(first,))
    note = popup_note(one, PopupsState(open=(first, second)), "R1")
    assert note is not None and note.body == "The robot says: “Lift”"
    assert popup_note(one, one, "R1") is None
    assert popup_note(PopupsState(open=(first, second)), one, "R1") is None  # one closed: nothing new


def test_notification_choices_round_trip_and_bad_ones_are_refused() -> None:
    settings = Settings(notifications={"battery_low": False, "popup": True})
    text = format_settings(settings)
    assert "[notifications]\nbattery_low = false" in text and "popup" not in text.split("[notifications]")[1]
    assert parse_settings(text).notifications == {"battery_low": False}
    assert set(NOTIFICATION_KINDS) >= {"arrived", "failed", "docked", "battery_low", "link_lost", "popup"}
    with pytest.raises(SettingsError, match="unknown kind"):
        parse_settings("[notifications]\nfireworks = false\n")
    with pytest.raises(SettingsError, match="true or false"):
        parse_settings('[notifications]\npopup = "no"\n')

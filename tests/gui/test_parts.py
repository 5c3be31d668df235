"""Small parts of the view on their own: form validation, gauges, the key table."""

from __future__ import annotations

from dataclasses import replace

import gi
import pytest

from rtmu.control.commands import COMMANDS
from rtmu.model.observables import ConnectionState, LinkHealth, LinkLevel, OperatorState, Phase, RobotModel
from rtmu.ui.gauges import battery_fraction, wifi_bars
from rtmu.ui.keys import KeyRouter, bindings
from rtmu.ui.settings_dialog import validate
from rtmu.ui.toolbar import MOTION_REFRESH_S, StatusToolbar

gi.require_version("Gdk", "4.0")
gi.require_version("Gtk", "4.0")
from gi.repository import Gdk, Gtk  # noqa: E402


@pytest.mark.parametrize(
    ("host", "port", "field"),
    [
        ("", "7272", "host"),
        ("two words", "7272", "host"),
        ("robot.local", "", "port"),
        ("robot.local", "0", "port"),
        ("robot.local", "65536", "port"),
        ("robot.local", "72x", "port"),
    ],
)
def test_the_form_names_the_wrong_field(host: str, port: str, field: str) -> None:
    assert field in validate("lab", host, port, "", False)


@pytest.mark.parametrize("host", ["robot.local", "10.0.0.5", "::1", "fe80::1", "localhost", "pioneer-3"])
def test_good_hosts_pass(host: str) -> None:
    assert validate("lab", host, "7272", "", False) == {}


def test_remembering_a_password_needs_a_user_and_a_profile_needs_a_name() -> None:
    assert "remember" in validate("lab", "robot", "7272", "", True)
    assert validate("lab", "robot", "7272", "alice", True) == {}
    assert "name" in validate("  ", "robot", "7272", "", False)


def test_battery_gauge_levels() -> None:
    assert battery_fraction(None, 11.0) == 0.0
    assert battery_fraction(13.0, 11.0) == 1.0
    assert battery_fraction(12.0, 11.0) == pytest.approx(0.5)
    assert battery_fraction(10.0, 11.0) == 0.0
    assert battery_fraction(42.0, None, is_soc=True) == pytest.approx(0.42)


def test_wifi_bars_from_quality_or_signal() -> None:
    assert wifi_bars(None, None) == 0
    assert [wifi_bars(q, None) for q in (0, 10, 30, 60, 100)] == [0, 1, 2, 3, 4]
    assert [wifi_bars(None, s) for s in (-50, -60, -70, -80, -90)] == [4, 3, 2, 1, 0]


def test_every_bound_command_exists_and_keys_do_not_clash() -> None:
    seen: dict[tuple[int, int], str] = {}
    router = KeyRouter(hold=print, release=print, activate=print)
    for b in bindings():
        if b.held:
            assert b.held in COMMANDS and COMMANDS.get(b.held).hold, b.held
        for accel in b.accels:
            ok, keyval, mods = Gtk.accelerator_parse(accel)
            assert ok, accel
            key = (Gdk.keyval_to_lower(keyval), int(mods))
            assert key not in seen, f"{accel} is bound twice ({seen.get(key)} and {b.title})"
            seen[key] = b.title
    # Shift typed the key: "+" is Shift+= on most layouts, a capital W is Shift+w.
    shift = Gdk.ModifierType.SHIFT_MASK
    assert router.lookup(Gdk.KEY_plus, shift).action == "win.speed-up"  # type: ignore[union-attr]
    assert router.lookup(Gdk.KEY_W, shift).held == "drive_forward"  # type: ignore[union-attr]
    assert router.lookup(Gdk.KEY_Up, shift).action == "win.move-forward-1m"  # type: ignore[union-attr]
    assert router.lookup(Gdk.KEY_space, Gdk.ModifierType(0)).action == "win.stop"  # type: ignore[union-attr]
    assert router.lookup(Gdk.KEY_q, Gdk.ModifierType.CONTROL_MASK) is None  # left to the app accelerator


def test_the_map_note_follows_the_connection_phase_then_the_map() -> None:
    from rtmu.model.observables import ConnectionState, MapModel, Phase
    from rtmu.ui.notes import map_note

    here = dict(host="127.0.0.1", port=7272)
    no_map = MapModel(state="none")
    ready = MapModel(state="ready")
    assert map_note(ConnectionState(Phase.DISCONNECTED), ready).startswith("Not connected: press Connect")
    assert "try again" in map_note(ConnectionState(Phase.FAILED, error="refused"), no_map)
    assert map_note(ConnectionState(Phase.CONNECTING, **here), MapModel()) == "Connecting to 127.0.0.1:7272…"
    assert map_note(ConnectionState(Phase.RECONNECTING, **here), ready).startswith(
        "Link lost: the robot is shown where"
    )
    connected = ConnectionState(Phase.CONNECTED, **here)
    assert map_note(connected, ready) == ""
    assert map_note(connected, MapModel(state="loading", received=12)) == "Loading the map… (12 packets)"
    assert map_note(connected, MapModel(state="failed", error="bad header")).endswith(": bad header")
    text = map_note(connected, no_map)
    assert "no map" in text and "grid" in text
    assert not any(ch.isdigit() for ch in text), "the grid step is the legend's, never repeated in the note"


def test_the_first_run_hint_never_breaks_rtmu_demo_across_lines() -> None:
    gi.require_version("Pango", "1.0")
    gi.require_version("PangoCairo", "1.0")
    from gi.repository import Pango, PangoCairo

    from rtmu.ui.application import FIRST_RUN_HINT
    from rtmu.ui.banners import _one_paragraph

    text = _one_paragraph(FIRST_RUN_HINT)  # what the banner shows
    start = text.index("rtmu\u2060")
    end = text.index("demo", start) + len("demo")
    byte_start, byte_end = len(text[:start].encode()), len(text[:end].encode())
    layout = Pango.Layout.new(PangoCairo.FontMap.get_default().create_context())
    layout.set_font_description(Pango.FontDescription.from_string("Sans 10.5"))
    layout.set_wrap(Pango.WrapMode.WORD)
    layout.set_text(text, -1)
    for width in range(120, 900, 7):
        layout.set_width(width * Pango.SCALE)
        for line in layout.get_lines_readonly():
            inside = byte_start < line.start_index < byte_end
            assert not inside, f"a line starts inside 'rtmu --demo' at {width} px"


def test_the_link_cell_says_when_the_server_does_not_answer_pings() -> None:
    model = RobotModel()
    model.connection.set(ConnectionState(Phase.CONNECTED, "127.0.0.1", 7272))
    model.health.set(LinkHealth(LinkLevel.OK, rtt_ms=1.5))
    toolbar = StatusToolbar(model, OperatorState(), status_age=lambda: 0.1)
    cell = toolbar.cells["link"]
    assert "ping" not in cell.value.get_text() and not cell.stale
    model.health.set(LinkHealth(LinkLevel.STALE, rtt_ms=None, ping_failures=2))
    assert cell.value.get_text() == "no ping ×2"
    assert cell.stale
    assert "not answering pings (2 in a row)" in (cell.get_tooltip_text() or "")
    model.health.set(LinkHealth(LinkLevel.OK, rtt_ms=1.5))
    assert "ping" not in cell.value.get_text() and "pings" not in (cell.get_tooltip_text() or "")
    toolbar.close()


def test_the_link_cell_shows_the_learned_stale_limit() -> None:
    model = RobotModel()
    model.connection.set(ConnectionState(Phase.CONNECTED, "127.0.0.1", 7272))
    model.health.set(LinkHealth(LinkLevel.OK, rtt_ms=1.5, stale_limit=0.33, jitter_ms=90.0))
    model.robot.set(replace(model.robot.value, numbers_at=1.0))
    toolbar = StatusToolbar(model, OperatorState(), status_age=lambda: 0.1)
    cell = toolbar.cells["link"]
    assert cell.value.get_text() == "1.5 ms 0.1/0.33"
    assert "Stale after 0.33 s without status: learned from this link's jitter (90 ms)" in (
        cell.get_tooltip_text() or ""
    )
    toolbar.close()


def test_colour_states_are_also_words_in_the_toolbar() -> None:
    """Battery and link say in a visible word (and to a screen reader) what their colour says."""
    from rtmu.values.state import RobotState

    model = RobotModel()
    model.connection.set(ConnectionState(Phase.CONNECTED, "127.0.0.1", 7272))
    model.health.set(LinkHealth(LinkLevel.OK, rtt_ms=1.5))
    robot = RobotState(battery_v=12.5, battery_low=11.5, battery_shutdown=11.0, numbers_at=1.0)
    model.robot.set(robot)
    toolbar = StatusToolbar(model, OperatorState(), status_age=lambda: 0.1)
    battery, link = toolbar.cells["battery"], toolbar.cells["link"]
    heading = link.caption.get_text()
    assert battery.caption.get_text() == "Battery" and heading.startswith("Link")
    model.robot.set(RobotState(battery_v=11.3, battery_low=11.5, battery_shutdown=11.0, numbers_at=2.0))
    toolbar.refresh()
    assert battery.caption.get_text() == "Battery · LOW" and battery.has_css_class("low")
    model.robot.set(RobotState(battery_v=10.9, battery_low=11.5, battery_shutdown=11.0, numbers_at=3.0))
    toolbar.refresh()
    assert battery.caption.get_text() == "Battery · SHUTDOWN"
    model.health.set(LinkHealth(LinkLevel.LOST, rtt_ms=None))
    toolbar.refresh()
    assert link.caption.get_text() == f"{heading} · LOST"
    model.health.set(LinkHealth(LinkLevel.OK, rtt_ms=1.5))
    toolbar.refresh()
    assert link.caption.get_text() == heading
    toolbar.close()


def test_a_new_round_trip_waits_for_the_tick_and_a_level_shows_at_once() -> None:
    """At rest the link cell changes once a second (issue 28): a new round trip or learned limit is
    shown by the window's tick, a link that goes stale at once."""
    model = RobotModel()
    model.connection.set(ConnectionState(Phase.CONNECTED, "127.0.0.1", 7272))
    model.health.set(LinkHealth(LinkLevel.OK, rtt_ms=1.5, stale_limit=0.33))
    model.robot.set(replace(model.robot.value, numbers_at=1.0))
    toolbar = StatusToolbar(model, OperatorState(), status_age=lambda: 0.1)
    cell = toolbar.cells["link"]
    assert cell.value.get_text() == "1.5 ms 0.1/0.33"
    model.health.set(LinkHealth(LinkLevel.OK, rtt_ms=2.5, stale_limit=0.34))
    assert cell.value.get_text() == "1.5 ms 0.1/0.33", "re-laid out before the tick"
    toolbar.refresh()  # the window's once-a-second tick
    assert cell.value.get_text() == "2.5 ms 0.1/0.34"
    model.health.set(LinkHealth(LinkLevel.STALE, rtt_ms=2.5, stale_limit=0.34))
    assert cell.stale and cell.caption.get_text().endswith("STALE")
    toolbar.close()


def test_range_readings_do_not_refresh_the_toolbar_and_motion_refreshes_it_four_times_a_second() -> None:
    """A driving robot's laser and sonar change ten times a second and the toolbar shows neither; its
    pose refreshes the toolbar's dozen cells at most every ``MOTION_REFRESH_S``; anything else at once
    (issue 28: following a drive ≤ 5 % of a core)."""
    model = RobotModel()
    model.connection.set(ConnectionState(Phase.CONNECTED, "127.0.0.1", 7272))
    model.robot.set(replace(model.robot.value, numbers_at=1.0, x=1000.0))
    now = [100.0]
    toolbar = StatusToolbar(model, OperatorState(), clock=lambda: now[0], status_age=lambda: 0.1)
    refreshes = [0]
    shown = toolbar.refresh

    def counted() -> None:
        refreshes[0] += 1
        shown()

    toolbar.refresh = counted  # type: ignore[method-assign]
    for i in range(5):
        model.robot.set(replace(model.robot.value, laser=((i, 2 * i),), sonar=((i * 10, 0),)))
    assert refreshes[0] == 0
    model.robot.set(replace(model.robot.value, x=2000.0, laser=((9, 9),)))
    assert refreshes[0] == 0, "a pose right after the last refresh waits its turn"
    now[0] += MOTION_REFRESH_S
    model.robot.set(replace(model.robot.value, x=3000.0))
    assert refreshes[0] == 1 and toolbar.cells["x"].value.get_text() == "3.00"
    model.robot.set(replace(model.robot.value, battery_v=11.9))
    assert refreshes[0] == 2 and toolbar.cells["battery"].value.get_text() == "11.9 V", "not motion: at once"
    toolbar.close()

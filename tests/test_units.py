"""Numbers with units for people (``rtmu.base.units``): the operator's language's decimal and grouping
marks and its way of writing the unit, in German and in English/C; machine output stays plain."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pytest

from rtmu.base import i18n
from rtmu.base.units import UNITS, coordinates, duration, file_size, metres, percent, quantity
from rtmu.subcommands._status import status_line, status_object


@pytest.fixture
def english() -> Iterator[None]:
    i18n.use(["en"])
    yield


def test_german_writes_a_decimal_comma_and_groups_thousands_with_a_dot(german: None) -> None:
    assert i18n.number(1234.5, 1) == "1.234,5"
    assert quantity(1234.5, "m", 1) == "1.234,5 m"
    assert metres(1500) == "1,5 m"
    assert metres(-250, 2) == "-0,25 m"
    assert quantity(12.5, "V", 1) == "12,5 V"
    assert percent(2.4) == "2,4 %"
    assert percent(60) == "60 %"
    assert file_size(1_234_567) == "1,2 MB"
    assert duration(12.6) == "13 s"
    assert duration(5400) == "1,5 h"
    assert quantity(90, "deg") == "90°"


def test_english_and_c_write_a_decimal_point(english: None) -> None:
    assert i18n.number(1234.5, 1) in ("1234.5", "1,234.5")  # the C library's LC_NUMERIC (C: no grouping)
    assert quantity(1.5, "m", 1) == "1.5 m"
    assert metres(1500) == "1.5 m"
    assert percent(2.4) == "2.4 %"
    assert file_size(999) == "999 B"
    assert file_size(1_234_567) == "1.2 MB"
    assert file_size(5 * 10**12) == "5000 GB"
    assert duration(5.3) == "5.3 s"
    assert duration(240) == "4 min"


def test_without_a_catalogue_numbers_read_as_the_c_library_writes_them(english: None) -> None:
    """The marks are read from LC_NUMERIC once (issue 28: ``locale.format_string`` per number was most of
    the toolbar's cost while driving); every number still comes out as the C library formats it."""
    import locale

    for value in (0.0, -0.4, 0.5, 12.25, 999.999, 1234.5, -98765.4321, 1e9, 123456789.987):
        for digits in (0, 1, 2, 3):
            assert i18n.number(value, digits) == locale.format_string(f"%.{digits}f", value, grouping=True)


def test_coordinates_keep_the_two_numbers_apart_when_the_mark_is_a_comma(german: None) -> None:
    assert coordinates(1500, -2000) == "1,50; -2,00 m"
    i18n.use(["en"])
    assert coordinates(1500, -2000) == "1.50, -2.00 m"


def test_every_unit_is_translated_in_german_with_its_value_kept(german: None) -> None:
    for unit in UNITS:
        assert "{value}" in i18n._(UNITS[unit]), unit


def test_a_catalogue_whose_number_pattern_is_unreadable_falls_back_to_the_c_library(
    tmp_path: Path, english: None
) -> None:
    """A translator's slip ("1234" for the pattern) must not break every number in the window."""
    from babel.messages.catalog import Catalog
    from babel.messages.mofile import write_mo

    catalog = Catalog(locale="xx", domain=i18n.DOMAIN)
    catalog.add(i18n.NUMBER_PATTERN, "eintausend")
    catalog.add(UNITS["m"], "{value} Meter")
    mo = tmp_path / "xx" / "LC_MESSAGES" / f"{i18n.DOMAIN}.mo"
    mo.parent.mkdir(parents=True)
    with mo.open("wb") as out:
        write_mo(out, catalog)
    i18n.use(["xx"], tmp_path)
    try:
        assert quantity(2.5, "m", 1) == "2.5 Meter"
    finally:
        i18n.use(["en"])


def test_the_status_line_is_german_and_the_json_object_stays_plain(german: None) -> None:
    from rtmu.values.state import RobotState

    robot = RobotState(
        x=12345, y=-20, th=90, vel=350, rot_vel=5, battery_v=12.5, status="Stopped", mode="Ready"
    )
    obj = status_object(robot)
    line = status_line(obj)
    assert "x=12.345 mm" in line and "Akku=12,5 V" in line and "v=350 mm/s" in line, line
    assert json.loads(json.dumps(obj)) == {
        "x": 12345,
        "y": -20,
        "th": 90,
        "vel": 350,
        "rot_vel": 5,
        "battery_v": 12.5,
        "status": "Stopped",
        "mode": "Ready",
    }


def test_a_said_sentence_is_english_for_machines_and_german_for_people(german: None) -> None:
    from rtmu.base.i18n import N_, Said, words
    from rtmu.base.units import Quantity

    said = Said(
        N_("connected to {where} in {time}"), where="robot.local:7272", time=Quantity(1234.5, "ms", 1)
    )
    assert said == "connected to robot.local:7272 in 1234.5 ms"
    assert json.loads(json.dumps({"summary": said})) == {
        "summary": "connected to robot.local:7272 in 1234.5 ms"
    }
    assert words(said) == "verbunden mit robot.local:7272 in 1.234,5 ms"
    nested = Said(N_("{what} — {advice}"), what=said, advice="x")
    assert words(nested).startswith("verbunden mit")
    assert words("robot.local") == "robot.local"
    import pickle

    assert words(pickle.loads(pickle.dumps(said))) == words(said)


def test_the_link_timing_a_stop_names_is_english_in_logs_and_german_on_screen(german: None) -> None:
    from rtmu.base.i18n import words
    from rtmu.base.link_timing import Timing

    timing = Timing(limit=0.33, jitter=0.09, mean=0.1, samples=50, learning=False).describe()
    assert timing == "learned jitter 90 ms, limit 0.33 s"
    assert words(timing) == "gelernter Jitter 90 ms, Grenze 0,33 s"


def test_live_videos_slow_down_and_the_speed_cap_source_read_german(german: None) -> None:
    from dataclasses import replace

    from rtmu.base.i18n import words
    from rtmu.client.video_feed import RateGovernor
    from rtmu.control.motion_limits import RobotLimits
    from rtmu.values.state import VideoStatus

    governor = RateGovernor(12.0, rtt_limit=0.2)
    governor.observe(0.0, 1.5, None)
    assert governor.reason == "slowed to 6.0 fps: round trip 1500 ms"  # --json and logs
    status = VideoStatus(6.0, 310.0, 45.0, 12.0, 6.0, governor.reason, False, 0, "")
    assert status.caption() == "6,0 fps · 310 kB/s · 45 ms alt · gedrosselt auf 6,0 fps: Umlaufzeit 1.500 ms"
    seen = RobotLimits().seen(1200.0, 100.0, 50.0)
    assert seen.source == "seen: 1200 mm/s at 50 % of full"
    assert words(seen.source) == "beobachtet: 1.200 mm/s bei 50 % der vollen Fahrt"
    assert words(replace(seen, source=RobotLimits().source).source) == "angenommen nach ARIAs P3-DX"


def test_a_number_typed_as_german_writes_it_is_read_back(german: None) -> None:
    """The map editor's fields read what the operator types in their language's way."""
    assert i18n.parse_number("1.234,5") == 1234.5
    assert i18n.parse_number(" −2,5 ") == -2.5
    assert i18n.parse_number(i18n.number(-12345.6, 1)) == -12345.6
    assert i18n.parse_number("2500") == 2500.0
    for wrong in ("", "zwei", "1_000", "nan", "inf", "1,2,3"):
        with pytest.raises(ValueError):
            i18n.parse_number(wrong)


def test_a_number_typed_in_english_or_c_is_read_back(english: None) -> None:
    assert i18n.parse_number("1234.5") == 1234.5
    assert i18n.parse_number(i18n.number(1234.5, 1)) == 1234.5
    assert i18n.parse_number("-0.25") == -0.25
    with pytest.raises(ValueError):
        i18n.parse_number("1,5.5.5")

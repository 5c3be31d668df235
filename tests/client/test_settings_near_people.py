"""The near-people speed cap is remembered in settings.toml: on/off and its speed, checked on the way in."""

from __future__ import annotations

import pytest

from rtmu.settings.store import Settings, SettingsError, format_settings, parse_settings


def test_off_and_the_default_speed_write_nothing() -> None:
    text = format_settings(Settings())
    assert "near_people" not in text
    back = parse_settings(text)
    assert (back.near_people, back.near_people_mm_s) == (False, None)


def test_on_and_a_chosen_speed_round_trip() -> None:
    text = format_settings(Settings(near_people=True, near_people_mm_s=300))
    assert "near_people = true" in text and "near_people_mm_s = 300" in text
    back = parse_settings(text)
    assert (back.near_people, back.near_people_mm_s) == (True, 300)


@pytest.mark.parametrize(
    "line",
    ['near_people = "yes"', "near_people_mm_s = 5000", "near_people_mm_s = 2.5", "near_people_mm_s = 0"],
)
def test_a_bad_value_is_refused_with_its_name(line: str) -> None:
    with pytest.raises(SettingsError, match="near_people"):
        parse_settings(f"version = 1\n{line}\n")

"""The Layers choices in settings.toml: per server, exact names, bounded, and a bad table refused."""

from __future__ import annotations

import pytest

from rtmu.settings.store import (
    MAX_LAYERS_PER_SERVER,
    Settings,
    SettingsError,
    format_settings,
    parse_settings,
)


def test_choices_round_trip_per_server_with_names_exactly_as_sent() -> None:
    s = Settings()
    s.layers = {
        "127.0.0.1:7272": {"sonarCurrent": False, "sim_lms2xx_1Current": True},
        "[::1]:7000": {'<b>x</b> "q"\\\n\x1b': False},
    }
    text = format_settings(s)
    assert '[layers."127.0.0.1:7272"]' in text and '"sonarCurrent" = false' in text
    assert "\x1b" not in text and "\n\x1b" not in text  # control characters are escaped in the file
    assert parse_settings(text).layers == s.layers


@pytest.mark.parametrize(
    "table",
    [
        "layers = 3",
        '[layers."a:1"]\n"x" = "yes"',
        '[layers."a:1"]\n"x" = 1',
        '[layers."a:1"]\n' + "\n".join(f'"n{i}" = true' for i in range(MAX_LAYERS_PER_SERVER + 1)),
    ],
)
def test_a_bad_layers_table_is_refused_as_not_ours(table: str) -> None:
    with pytest.raises(SettingsError):
        parse_settings(f"version = 1\n{table}\n")

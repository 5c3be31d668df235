"""Fleet profiles: a list of direct robots or a central server; one-robot profiles load and save as before."""

from __future__ import annotations

from pathlib import Path

import pytest

from rtmu.client.roster import RobotAdded, RobotEndpoint, RosterEvent
from rtmu.fleet.sessions import direct_roster, robot_profile
from rtmu.settings.store import (
    DirectRobot,
    Profile,
    Settings,
    SettingsError,
    format_settings,
    load_settings,
    parse_central,
    parse_settings,
)

OLD_FILE = """version = 1
last_profile = "lab"

[profiles."lab"]
host = "10.0.0.5"
port = 7272
user = "alice"
speed = 60
"""


def test_a_profile_from_before_fleets_loads_and_saves_unchanged() -> None:
    settings = parse_settings(OLD_FILE)
    lab = settings.profiles["lab"]
    assert (lab.host, lab.port, lab.user, lab.robots, lab.central, lab.is_fleet) == (
        "10.0.0.5", 7272, "alice", (), "", False)  # fmt: skip
    text = format_settings(settings)
    assert "robots" not in text and "central" not in text
    assert parse_settings(text) == settings


def test_a_robot_list_round_trips_and_becomes_a_direct_roster() -> None:
    robots = (DirectRobot("robot1", "127.0.0.1", 7272), DirectRobot('robot "2"', "10.0.0.6", 7300))
    settings = Settings({"floor": Profile("floor", user="bob", robots=robots)}, "floor")
    again = parse_settings(format_settings(settings))
    assert again == settings and again.profiles["floor"].is_fleet
    roster = direct_roster(again.profiles["floor"])
    assert roster is not None
    heard: list[RosterEvent] = []
    roster.start(heard.append)
    assert heard == [RobotAdded(RobotEndpoint(r.name, r.host, r.port)) for r in robots]
    one = robot_profile(again.profiles["floor"], RobotEndpoint("robot1", "127.0.0.1", 7272))
    assert (one.name, one.host, one.port, one.user, one.robots, one.is_fleet) == (
        "robot1", "127.0.0.1", 7272, "bob", (), False)  # fmt: skip
    assert direct_roster(Profile("one")) is None


def test_a_central_server_profile_round_trips() -> None:
    settings = Settings({"c": Profile("c", central="10.0.0.2:7272")}, "c")
    again = parse_settings(format_settings(settings))
    assert again.profiles["c"].central == "10.0.0.2:7272" and again.profiles["c"].is_fleet
    assert parse_central("10.0.0.2:7000") == ("10.0.0.2", 7000)
    assert parse_central("central.lan") == ("central.lan", 7272)


@pytest.mark.parametrize(
    ("body", "why"),
    [
        ('robots = "robot1"', "list of tables"),
        ('robots = [{ name = "a" }]', "name, host and port"),
        ('robots = [{ name = "a", host = "h", port = "7272" }]', "port must be int"),
        ('robots = [{ name = "a", host = "h", extra = 1 }]', "name, host and port"),
        ('robots = [{ name = "a", host = "h", port = 70000 }]', "not 1…65535"),
        ('robots = [{ name = "a", host = "h" }, { name = "a", host = "i" }]', "same name"),
        ('central = "nohost:"', "not HOST:PORT"),
        ('central = "h:99999"', "not HOST:PORT"),
        ('central = "h:1"\nrobots = [{ name = "a", host = "h" }]', "not both"),
        ("robots = [" + ", ".join(f'{{ name = "r{i}", host = "h" }}' for i in range(101)) + "]", "more than"),
    ],
)
def test_a_bad_fleet_profile_is_refused_with_its_reason(body: str, why: str) -> None:
    with pytest.raises(SettingsError, match=why):
        parse_settings(f'version = 1\n[profiles."f"]\n{body}\n')


def test_a_bad_fleet_file_on_disk_gives_one_warning_and_is_kept(tmp_path: Path) -> None:
    path = tmp_path / "settings.toml"
    path.write_text('version = 1\n[profiles."f"]\nrobots = [{ name = "<b>x</b>", host = "" }]\n')
    loaded = load_settings(path)
    assert loaded.settings.profiles == {} and loaded.warning is not None and "bad host" in loaded.warning
    assert loaded.moved_to is not None and loaded.moved_to.exists()

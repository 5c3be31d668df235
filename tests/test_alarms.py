"""Alarm levels with hysteresis: one event (one beep) per crossing, never a stream; hostile values ignored."""

from __future__ import annotations

import math

import pytest

from rtmu.control.alarms import Alarm, AlarmMonitor, Severity
from rtmu.values.state import LinkHealth, LinkLevel, RobotState

OK = LinkHealth(LinkLevel.OK, rtt_ms=5.0)
VOLTS = RobotState(battery_v=13.0, battery_low=11.5, battery_shutdown=11.0)


def battery(monitor: AlarmMonitor, volts: float) -> list[tuple[Severity, bool]]:
    robot = RobotState(battery_v=volts, battery_low=11.5, battery_shutdown=11.0)
    return [(e.severity, e.sound) for e in monitor.update(robot, OK) if e.alarm is Alarm.BATTERY]


def test_battery_low_then_critical_beeps_once_per_crossing() -> None:
    m = AlarmMonitor()
    assert battery(m, 13.0) == []
    assert battery(m, 11.5) == [(Severity.WARNING, True)]
    assert battery(m, 11.4) == [] and battery(m, 11.45) == []
    assert battery(m, 11.0) == [(Severity.CRITICAL, True)]
    assert battery(m, 11.1) == [], "inside the margin over shutdown: still critical"
    assert battery(m, 11.3) == [(Severity.WARNING, False)], "better: no beep"
    assert battery(m, 11.6) == [], "inside the margin over low: still low"
    assert battery(m, 11.8) == [(Severity.CLEAR, False)]


def test_a_voltage_hovering_at_the_threshold_raises_once() -> None:
    m = AlarmMonitor()
    sounds = 0
    for i in range(200):
        volts = 11.5 + (0.05 if i % 2 else -0.05)
        sounds += sum(s for _sev, s in battery(m, volts))
    assert sounds == 1
    assert m.severity(Alarm.BATTERY) is Severity.WARNING


def test_state_of_charge_uses_the_servers_levels_or_defaults() -> None:
    m = AlarmMonitor()
    robot = RobotState(battery_v=50.0, battery_is_soc=True)
    assert m.update(robot, OK) == []
    events = m.update(RobotState(battery_v=19.0, battery_is_soc=True), OK)
    assert [(e.alarm, e.severity) for e in events] == [(Alarm.BATTERY, Severity.WARNING)]
    assert "19 %" in events[0].text
    events = m.update(RobotState(battery_v=30.0, battery_low=35.0, battery_is_soc=True), OK)
    assert events == [], "the server's own low level (35 %) keeps it low"


def test_volts_without_levels_raise_nothing() -> None:
    m = AlarmMonitor()
    assert m.update(RobotState(battery_v=1.0), OK) == []


def test_wifi_quality_hysteresis() -> None:
    m = AlarmMonitor()

    def wifi(q: int) -> list[tuple[Severity, bool]]:
        return [
            (e.severity, e.sound) for e in m.update(RobotState(wifi_quality=q), OK) if e.alarm is Alarm.WIFI
        ]

    assert wifi(86) == []
    assert wifi(27) == [(Severity.WARNING, True)]
    assert wifi(31) == [] and wifi(39) == [] and wifi(14) == []
    assert wifi(40) == [(Severity.CLEAR, False)]
    assert wifi(30) == []


def test_the_wifi_alarm_says_the_percent_the_toolbar_shows() -> None:
    """One unit: the banner said "10/70" where the toolbar said "14 %" (issue 21)."""
    m = AlarmMonitor()
    (event,) = m.update(RobotState(wifi_quality=14), OK)
    assert event.text == "Weak Wi-Fi on the robot: link quality 14 %"
    assert m.update(RobotState(wifi_quality=20), OK) == [], "no new event, no beep"
    assert m.words[Alarm.WIFI] == "Weak Wi-Fi on the robot: link quality 20 %", "the words follow the value"
    m.update(RobotState(wifi_quality=50), OK)
    assert Alarm.WIFI not in m.words


def test_round_trip_and_unanswered_pings() -> None:
    m = AlarmMonitor()

    def rtt(ms: float | None, failures: int = 0) -> list[Severity]:
        h = LinkHealth(LinkLevel.OK, rtt_ms=ms, ping_failures=failures)
        return [e.severity for e in m.update(RobotState(), h) if e.alarm is Alarm.RTT]

    assert rtt(50) == []
    assert rtt(450) == [Severity.WARNING]
    assert rtt(300) == [] and rtt(None) == []
    assert rtt(150) == [Severity.CLEAR]
    assert rtt(None, failures=2) == [Severity.WARNING]
    assert rtt(30) == [Severity.CLEAR]


def test_disconnecting_clears_every_alarm_silently() -> None:
    m = AlarmMonitor()
    m.update(RobotState(battery_v=11.0, battery_low=11.5, battery_shutdown=10.0, wifi_quality=5), OK)
    assert set(m.active) == {Alarm.BATTERY, Alarm.WIFI}
    events = m.update(RobotState(), LinkHealth(LinkLevel.DOWN))
    assert {e.alarm for e in events} == {Alarm.BATTERY, Alarm.WIFI}
    assert all(e.severity is Severity.CLEAR and not e.sound for e in events)
    assert m.active == {}


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_hostile_readings_are_no_readings(bad: float) -> None:
    m = AlarmMonitor()
    m.update(RobotState(battery_v=11.2, battery_low=11.5, battery_shutdown=11.0), OK)
    assert m.severity(Alarm.BATTERY) is Severity.WARNING
    robot = RobotState(battery_v=bad, battery_low=bad, battery_shutdown=bad, wifi_quality=bad)  # type: ignore[arg-type]
    assert m.update(robot, LinkHealth(LinkLevel.OK, rtt_ms=bad)) == []
    assert m.severity(Alarm.BATTERY) is Severity.WARNING


def test_the_mute_is_remembered_in_settings_and_checked() -> None:
    from rtmu.settings.store import Settings, SettingsError, format_settings, parse_settings

    assert parse_settings(format_settings(Settings())).alarms_muted is False
    text = format_settings(Settings(alarms_muted=True))
    assert "alarms_muted = true" in text and parse_settings(text).alarms_muted is True
    with pytest.raises(SettingsError, match="alarms_muted"):
        parse_settings('version = 1\nalarms_muted = "yes"\n')


@pytest.mark.parametrize(
    "docked",
    [{"dock_state": "Docked"}, {"status": "Docked"}],
    ids=["dockInfo", "status"],
)
def test_a_low_battery_on_its_dock_is_charging_not_an_alarm(docked: dict[str, str]) -> None:
    """ "Bring the robot to its charger" is a lie once it is there: docked, the low banner gives way to a
    charging note; undocked while still low, it is raised (and beeps) again (issue 21)."""
    m = AlarmMonitor()
    low = RobotState(battery_v=11.4, battery_low=11.5, battery_shutdown=11.0)
    assert [(e.severity, e.sound) for e in m.update(low, OK)] == [(Severity.WARNING, True)]
    on_dock = RobotState(battery_v=11.4, battery_low=11.5, battery_shutdown=11.0, **docked)  # type: ignore[arg-type]
    events = m.update(on_dock, OK)
    assert [(e.severity, e.text) for e in events] == [
        (Severity.CLEAR, "Battery low (11.4 V), charging on its dock")
    ]
    assert m.update(on_dock, OK) == [], "said once"
    assert [(e.severity, e.sound) for e in m.update(low, OK)] == [(Severity.WARNING, True)], "undocked"
    critical = RobotState(battery_v=10.9, battery_low=11.5, battery_shutdown=11.0, **docked)  # type: ignore[arg-type]
    assert [e.severity for e in m.update(critical, OK)] == [Severity.CRITICAL], "critical even docked"
    undocking = RobotState(battery_v=11.4, battery_low=11.5, battery_shutdown=11.0, dock_state="Undocking")
    assert [e.severity for e in m.update(undocking, OK)] == [Severity.WARNING]

"""Alarms for a weak link and a low battery: levels with hysteresis, one event per crossing. GTK-free.

The window (``rtmu.ui.alarm_view``) shows each active alarm as a banner and beeps
once when one is raised or gets worse; nothing here knows about GTK or sound.

Why hysteresis: a Wi-Fi quality or a battery voltage hovering at its threshold
would otherwise raise and clear an alarm every second — a beep every second
teaches the operator to mute it. An alarm is raised when its value crosses the
*raise* level and cleared only once it is back past the *clear* level.

Levels (the server's own words where it publishes them):

* **Battery**: ``batteryInfo``'s low and shutdown levels, volts or state of charge
  (:attr:`RobotState.battery_low` / ``battery_shutdown``); low is a warning, at or
  under shutdown it is critical. A robot that gives no levels gets none in volts
  (a pack's voltage says nothing without them) and 20 % / 5 % in state of charge.
  A docked robot is where the low warning sends the operator: docked (``dockInfo``,
  or ARNL's "Docked" status), low is no alarm but a short "charging" note; undocked
  while still low, it is raised again. Critical stays critical on the dock.
* **Wi-Fi**: the link quality the server publishes (``getStrings``' "Wireless Link
  Quality", the kernel's 0–70 scale), in % as the toolbar shows it: under
  :attr:`Thresholds.wifi_low` is a warning.
* **Round trip**: the client's ping time (``LinkHealth.rtt_ms``) over
  :attr:`Thresholds.rtt_high_ms`, or unanswered pings, is a warning. A stale or lost
  link has its own banner already; without a connection every alarm clears silently.

Values from the network are untrusted: a NaN, an infinity or a missing value is no
reading — the alarm keeps its state until a real one comes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum, IntEnum

from ..base.i18n import _
from ..base.units import quantity
from ..client.nav_status import read_status
from ..values.state import LinkHealth, LinkLevel, NavOutcome, RobotState


class Alarm(Enum):
    BATTERY = "battery"
    WIFI = "wifi"
    RTT = "rtt"


class Severity(IntEnum):
    CLEAR = 0
    WARNING = 1
    CRITICAL = 2


@dataclass(frozen=True, slots=True)
class Thresholds:
    wifi_low: float = 29.0
    """Quality (%) under which the Wi-Fi alarm is raised (20 of Linux's 70: ≈ −90 dBm)."""
    wifi_clear: float = 40.0
    """Quality (%) at which it clears (28 of 70)."""
    rtt_high_ms: float = 400.0
    rtt_clear_ms: float = 200.0
    ping_failures: int = 2
    """Unanswered pings in a row that count as a weak link."""
    battery_margin_v: float = 0.2
    """How far over a battery level (volts) the value must come back to clear."""
    battery_margin_pct: float = 3.0
    soc_low_pct: float = 20.0
    """State-of-charge levels for a robot that reports a percentage but no levels."""
    soc_shutdown_pct: float = 5.0


@dataclass(frozen=True, slots=True)
class AlarmEvent:
    """An alarm changed severity: ``sound`` when it was raised or got worse (once per crossing)."""

    alarm: Alarm
    severity: Severity
    text: str
    sound: bool = False
    """Raised or got worse: beep (a change for the better, or a clear, is silent)."""


class AlarmMonitor:
    """Feed it the robot and link values as they change; it returns the alarms that changed."""

    def __init__(self, thresholds: Thresholds | None = None) -> None:
        self.t = thresholds or Thresholds()
        self._severity: dict[Alarm, Severity] = dict.fromkeys(Alarm, Severity.CLEAR)
        self.words: dict[Alarm, str] = {}
        """What each active alarm says with the latest value ("… link quality 20 %"): a banner
        raised at 14 % shows the number the toolbar shows now, without a new event or beep."""

    def severity(self, alarm: Alarm) -> Severity:
        return self._severity[alarm]

    @property
    def active(self) -> dict[Alarm, Severity]:
        return {a: s for a, s in self._severity.items() if s is not Severity.CLEAR}

    def update(self, robot: RobotState, health: LinkHealth) -> list[AlarmEvent]:
        """The alarms whose severity changed with these values (raised, worse, better or cleared)."""
        if health.level is LinkLevel.DOWN:
            return self._set_all_clear()
        events: list[AlarmEvent] = []
        self._battery(robot, events)
        self._wifi(robot, events)
        self._rtt(health, events)
        return events

    def _set_all_clear(self) -> list[AlarmEvent]:
        """No connection: the connection banner speaks now; every alarm clears, silently."""
        events = [AlarmEvent(a, Severity.CLEAR, "") for a, s in self._severity.items() if s]
        self._severity = dict.fromkeys(Alarm, Severity.CLEAR)
        self.words = {}
        return events

    # -- each alarm ------------------------------------------------------------------------------
    def _battery(self, robot: RobotState, events: list[AlarmEvent]) -> None:
        value = _reading(robot.battery_v)
        if value is None:
            return
        soc = robot.battery_is_soc
        low = _reading(robot.battery_low)
        shutdown = _reading(robot.battery_shutdown)
        if soc:
            low = self.t.soc_low_pct if low is None else low
            shutdown = self.t.soc_shutdown_pct if shutdown is None else shutdown
        margin = self.t.battery_margin_pct if soc else self.t.battery_margin_v
        was = self._severity[Alarm.BATTERY]
        if shutdown is not None and value <= shutdown + (margin if was is Severity.CRITICAL else 0.0):
            now = Severity.CRITICAL
        elif low is not None and value <= low + (margin if was is not Severity.CLEAR else 0.0):
            now = Severity.WARNING
        else:
            now = Severity.CLEAR
        shown = quantity(value, "%") if soc else quantity(value, "V", 1)
        text = {
            Severity.CRITICAL: _("Battery critical: {shown} — the robot is about to shut down"),
            Severity.WARNING: _("Battery low: {shown} — bring the robot to its charger"),
            Severity.CLEAR: _("Battery back to {shown}"),
        }[now].format(shown=shown)
        if now is Severity.WARNING and _docked(robot):
            now, text = Severity.CLEAR, _("Battery low ({shown}), charging on its dock").format(shown=shown)
        self._change(Alarm.BATTERY, now, text, events)

    def _wifi(self, robot: RobotState, events: list[AlarmEvent]) -> None:
        quality = _reading(robot.wifi_quality)
        if quality is None:
            return
        was = self._severity[Alarm.WIFI]
        if quality < self.t.wifi_low:
            now = Severity.WARNING
        elif quality >= self.t.wifi_clear:
            now = Severity.CLEAR
        else:
            now = was
        text = (
            _("Weak Wi-Fi on the robot: link quality {quality}").format(quality=quantity(quality, "%"))
            if now
            else _("Wi-Fi back: link quality {quality}").format(quality=quantity(quality, "%"))
        )
        self._change(Alarm.WIFI, now, text, events)

    def _rtt(self, health: LinkHealth, events: list[AlarmEvent]) -> None:
        rtt = _reading(health.rtt_ms)
        failures = health.ping_failures
        was = self._severity[Alarm.RTT]
        if failures >= self.t.ping_failures:
            now, text = (
                Severity.WARNING,
                _("Weak link: {failures} pings unanswered").format(failures=failures),
            )
        elif rtt is None:
            return
        elif rtt > self.t.rtt_high_ms:
            now, text = Severity.WARNING, _("Weak link: round trip {rtt}").format(rtt=quantity(rtt, "ms"))
        elif rtt < self.t.rtt_clear_ms and failures == 0:
            now, text = Severity.CLEAR, _("Link back: round trip {rtt}").format(rtt=quantity(rtt, "ms"))
        else:
            now, text = was, _("Weak link: round trip {rtt}").format(rtt=quantity(rtt, "ms"))
        self._change(Alarm.RTT, now, text, events)

    def _change(self, alarm: Alarm, now: Severity, text: str, events: list[AlarmEvent]) -> None:
        if now is Severity.CLEAR:
            self.words.pop(alarm, None)
        else:
            self.words[alarm] = text
        if now is self._severity[alarm]:
            return
        worse = now > self._severity[alarm]
        self._severity[alarm] = now
        events.append(AlarmEvent(alarm, now, text, sound=worse))


def _docked(robot: RobotState) -> bool:
    """On its charger: ``dockInfo`` says Docked, or (a server without it) ARNL's status does."""
    if robot.dock_state is not None:
        return robot.dock_state == "Docked"
    return read_status(robot.status).phase is NavOutcome.DOCKED


def _reading(value: float | None) -> float | None:
    """A value from the network, or None when it is no usable reading (missing, NaN, infinite)."""
    if value is None or isinstance(value, bool):
        return None
    try:
        number = float(value)
    except (TypeError, ValueError):
        return None
    return number if math.isfinite(number) else None

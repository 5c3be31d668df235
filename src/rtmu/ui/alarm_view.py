"""The alarms on screen: a banner per active alarm and one short beep per crossing, with a mute.

``rtmu.control.alarms`` decides (levels, hysteresis); this shows. Never a modal dialog:
each alarm is a banner of its own topic (``alarm:battery`` …) that stays while
the alarm is active and goes when it clears (a clear says so for a few
seconds). The sound is the display's bell (:meth:`Gdk.Display.beep`): it
needs no sound server or extra package on Debian 12, and a desktop maps it to
its alert sound. ``beeps`` counts the sounds asked for (what tests can see:
Xvfb has no loudspeaker).
"""

from __future__ import annotations

from collections.abc import Callable

from ..control.alarms import Alarm, AlarmEvent, AlarmMonitor, Severity
from ..model.observables import RobotModel
from .banners import BannerStack

LEVEL = {Severity.WARNING: "warning", Severity.CRITICAL: "error"}
CLEARED_FOR = 4.0
"""Seconds the "back to normal" banner stays."""


class AlarmView:
    """Watches one robot's model; ``beep()`` makes the sound; ``muted`` silences it (banners stay)."""

    def __init__(
        self, model: RobotModel, banners: BannerStack, beep: Callable[[], None], *, muted: bool = False
    ) -> None:
        self.model = model
        self.banners = banners
        self.beep = beep
        self.muted = muted
        self.monitor = AlarmMonitor()
        self.beeps = 0
        self.sounded: list[Alarm] = []
        """The alarm of each beep, in order."""
        self.events: list[AlarmEvent] = []
        """Every change shown, newest last (bounded): for tests and the details view."""
        self._unobserve = [
            model.robot.observe(lambda _o, _n: self.update()),
            model.health.observe(lambda _o, _n: self.update()),
        ]
        self.update()

    @staticmethod
    def topic(alarm: Alarm) -> str:
        return f"alarm:{alarm.value}"

    def update(self) -> None:
        for event in self.monitor.update(self.model.robot.value, self.model.health.value):
            self.events = [*self.events[-49:], event]
            topic = self.topic(event.alarm)
            if event.severity is Severity.CLEAR:
                if event.text:
                    self.banners.tell(topic, "info", event.text, timeout=CLEARED_FOR)
                else:
                    self.banners.dismiss(topic)
                continue
            self.banners.tell(topic, LEVEL[event.severity], event.text, timeout=None)
            if event.sound and not self.muted:
                self.beeps += 1
                self.sounded.append(event.alarm)
                self.beep()
        for alarm, words in self.monitor.words.items():  # the latest value, as the toolbar shows it
            topic = self.topic(alarm)
            shown = self.banners.text(topic)
            if shown is not None and shown != words:
                level = LEVEL[self.monitor.severity(alarm)]
                self.banners.tell(topic, level, words, timeout=None)

    def close(self) -> None:
        for remove in self._unobserve:
            remove()
        self._unobserve = []

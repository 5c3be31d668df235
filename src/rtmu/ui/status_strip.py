"""The phone layout's one-line status: battery, Wi-Fi, link, throttle and mode in 360 px.

The full status toolbar needs ~800 px; on a portrait phone it would be a row of
hidden columns. The strip keeps what decides whether to keep driving — battery
(amber low, red critical), the robot's Wi-Fi, the link's round trip or state,
the throttle — and the mode, ellipsized into what is left. Plain text labels
(mode strings are the server's words).
"""

from __future__ import annotations

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
from gi.repository import Gtk, Pango  # noqa: E402

from ..base.i18n import N_, _  # noqa: E402
from ..base.units import quantity  # noqa: E402
from ..control.alarms import Thresholds  # noqa: E402
from ..model.observables import LinkLevel, OperatorState, Phase, RobotModel  # noqa: E402
from . import accessible  # noqa: E402

DASH = "—"
SLOW_MS = Thresholds().rtt_high_ms
STATE_WORDS = {
    "low": "low",
    "critical": N_("at shutdown level"),
    "stale": N_("slow or stale"),
    "lost": "lost",
}
"""The words for each colour of the strip (amber, red): a screen reader hears the state, too."""


class StatusStrip(Gtk.Box):
    """See the module notes. ``labels`` by name: battery, wifi, link, speed, mode."""

    def __init__(self, model: RobotModel, operator: OperatorState) -> None:
        super().__init__(orientation=Gtk.Orientation.HORIZONTAL, spacing=6, visible=False)
        self.add_css_class("status-strip")
        self.model = model
        self.operator = operator
        self.labels: dict[str, Gtk.Label] = {}
        self._said: dict[str, str] = {}
        for name, chars in (("battery", 6), ("wifi", 5), ("link", 5), ("speed", 4), ("mode", 3)):
            label = Gtk.Label(xalign=0.0, width_chars=chars)
            label.set_use_markup(False)
            # A language with longer words must not push the strip out of a 360 px screen: each part
            # gives way down to its own width (tests/gui/test_pseudo_locale.py).
            label.set_ellipsize(Pango.EllipsizeMode.END)
            label.add_css_class(f"strip-{name}")
            self.labels[name] = label
            self.append(label)
        mode = self.labels["mode"]
        mode.set_ellipsize(Pango.EllipsizeMode.END)
        mode.set_hexpand(True)
        self._unobserve = [
            model.robot.observe(self._changed),
            model.health.observe(self._changed),
            model.connection.observe(self._changed),
            operator.speed.observe(self._changed),
        ]
        self.refresh()

    def _changed(self, _old: object, _new: object) -> None:
        if self.get_visible():  # hidden in landscape: no work at 10 Hz; shown → refreshed by the layout
            self.refresh()

    @property
    def text(self) -> str:
        return " | ".join(label.get_text() for label in self.labels.values())

    def refresh(self) -> None:
        robot, health = self.model.robot.value, self.model.health.value
        connected = self.model.connection.value.phase is Phase.CONNECTED
        if robot.battery_v is None or not connected:
            battery = _("Bat {DASH}").format(DASH=DASH)
        elif robot.battery_is_soc:
            battery = _("Bat {battery}").format(battery=quantity(robot.battery_v, "%"))
        else:
            battery = _("Bat {battery}").format(battery=quantity(robot.battery_v, "V", 1))
        self._set("battery", battery, robot.battery_state if connected else "unknown")
        quality = robot.wifi_quality
        wifi = (
            DASH if quality is None or not connected else quantity(max(0, min(100, quality)), "%")
        )  # (in %)
        self._set("wifi", _("Wi-Fi {wifi}").format(wifi=wifi), "")
        if not connected:
            link, state = self.model.connection.value.phase.value, "lost"
        elif health.level is not LinkLevel.OK:
            link, state = health.level.value, "lost" if health.level is LinkLevel.LOST else "stale"
        else:
            link = quantity(health.rtt_ms, "ms") if health.rtt_ms is not None else "ok"
            slow = health.rtt_ms is not None and health.rtt_ms > SLOW_MS
            state = "stale" if slow else "ok"  # amber from where the round-trip alarm starts
        self._set("link", link, state)
        self._set("speed", quantity(self.operator.speed.value.percent, "%"), "")
        self._set("mode", robot.mode or robot.status or DASH, "")

    def _set(self, name: str, text: str, state: str) -> None:
        label = self.labels[name]
        if label.get_text() != text:
            label.set_text(text)
        for css in ("low", "critical", "ok", "stale", "lost"):
            (label.add_css_class if css == state else label.remove_css_class)(css)
        # what the colour says, for a screen reader
        words = _(STATE_WORDS[state]) if state in STATE_WORDS else ""
        if self._said.get(name, "") != words:  # said once per change, not at 10 Hz
            self._said[name] = words
            accessible.describe(label, f"{name} {words}" if words else "")

    def close(self) -> None:
        for remove in self._unobserve:
            remove()
        self._unobserve = []

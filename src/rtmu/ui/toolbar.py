"""The status toolbar: pose, motion, battery, Wi-Fi, mode, safe drive, throttle and link health.

Values come from the model; :meth:`StatusToolbar.refresh` runs on the window's
timer as well, because *age* changes without any new value: a value older than
:data:`STALE_AFTER` (or any value while the link is not OK) is greyed and its
tooltip says how old it is. Stale data never looks fresh. A value the server
does not publish (Wi-Fi on most servers) is greyed with a tooltip saying so. Ages are shown in
whole seconds (:func:`age_text`), so a connected window's labels change once a second at most,
not with every status packet, and a style class is touched only when it changes: each change
costs GTK a restyle and a repaint of the header.

Every column has a fixed width (its value label is exactly ``width_chars`` wide),
so nothing shifts sideways when "—" becomes "12.8 V". A narrow window hides the
least important columns first (:data:`HIDE_FIRST`) and shows them again when
there is room; speed, battery, mode and link always stay. The localization column (servers with
``getLocState``) gives way first while it says Good, and never while it says Lost or poor.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
from gi.repository import GLib, Gtk, Pango  # noqa: E402

from ..base.i18n import _, ngettext, number  # noqa: E402
from ..base.link_timing import STATUS_CEILING  # noqa: E402
from ..model.observables import (  # noqa: E402
    ConnectionState,
    LinkHealth,
    LinkLevel,
    OperatorState,
    Phase,
    RobotModel,
    RobotState,
)
from . import accessible  # noqa: E402
from .gauges import BatteryGauge, WifiGauge, battery_fraction, wifi_bars  # noqa: E402
from .ld_status import details_lines, goal_suffix  # noqa: E402
from .nav_text import loc_level, loc_text, outcome_status  # noqa: E402
from .notes import heading_text  # noqa: E402
from .state_words import level_word, phase_word  # noqa: E402

STALE_AFTER = 1.0
"""Seconds after which a pose/battery value is shown as stale (status arrives at 10 Hz)."""
MOTION_REFRESH_S = 0.25
"""A driving robot's pose and speeds refresh the toolbar at most 4 times a second (readable; each
refresh re-lays out the window's header: at 10 Hz 1.4 % of a core while following a drive, issue 28).
Any other change — battery, mode, link — shows at once."""


def age_text(seconds: float) -> str:
    """An age as the window shows it: whole seconds, then minutes, then hours."""
    if seconds < 60:
        return _("{seconds} s").format(seconds=int(seconds))
    if seconds < 3600:
        return _("{minutes} min").format(minutes=number(seconds / 60))
    return _("{hours} h").format(hours=number(seconds / 3600, 1))


DASH = "—"
HIDE_FIRST = ("rot", "th", "y", "x", "wifi", "safe", "speed")
"""Columns a narrow window gives up, in this order (the last one given up comes back first). The
speed (mm/s) is never given up: the operator must always see how fast the robot goes (a
1280×800 screen at ``GDK_SCALE=2`` is a 640 px window); the pose is on the map as well."""


class Cell(Gtk.Box):
    """A caption over a value, optionally with a small gauge before the value."""

    def __init__(self, caption: str, *, width_chars: int = 5, gauge: Gtk.Widget | None = None) -> None:
        super().__init__(orientation=Gtk.Orientation.VERTICAL, spacing=0)
        self.add_css_class("status-cell")
        self.caption = Gtk.Label(label=caption, xalign=0.0)
        self.caption.add_css_class("caption")
        self.value = Gtk.Label(label=DASH, xalign=0.0, width_chars=width_chars)
        self.value.add_css_class("value")
        self.value.set_use_markup(False)
        self.value.set_ellipsize(Pango.EllipsizeMode.END)
        self.value.set_max_width_chars(width_chars)  # = width_chars: a fixed column, whatever the text
        self.append(self.caption)
        row = Gtk.Box(orientation=Gtk.Orientation.HORIZONTAL, spacing=4)
        if gauge is not None:
            row.append(gauge)
        row.append(self.value)
        self.append(row)
        self.stale = False
        self._said = ""
        self._heading = caption
        self.mark = ""
        """A word the caption carries for a state its colour shows (``LOW``): not by colour alone."""
        self._tooltip: str | None = None
        self._level: str | None = None
        # The tooltip is answered when GTK asks (pointer over the cell): setting GTK's own text made it
        # query the tooltip under the pointer each time, and the link cell's words change every second
        # (its age): 2–10 ms of a still window's second on a small machine (issue 28).
        self.connect("query-tooltip", self._answer_tooltip)
        self._pointer_in = False
        self._tip: Gtk.Tooltip | None = None
        hover = Gtk.EventControllerMotion()
        hover.connect("enter", lambda *_a: setattr(self, "_pointer_in", True))
        hover.connect("leave", lambda *_a: setattr(self, "_pointer_in", False))
        self.add_controller(hover)

    def show_level(self, css_class: str | None) -> None:
        """One style class of a family (``link-ok``, ``link-stale`` …) in place of the one before."""
        if css_class != self._level:
            if self._level is not None:
                self.remove_css_class(self._level)
            if css_class is not None:
                self.add_css_class(css_class)
            self._level = css_class

    def show_value(
        self, text: str, *, stale: bool, tooltip: str | None = None, words: str = "", mark: str = ""
    ) -> None:
        """``words``: the state the value's colour shows (``low``, ``link stale``), for screen readers;
        ``mark``: the same in one visible word after the caption (``Battery · LOW``)."""
        if self.value.get_text() != text:
            self.value.set_text(text)
        if mark != self.mark:
            self.mark = mark
            self.caption.set_text(f"{self._heading} · {mark}" if mark else self._heading)
        said = ", ".join(w for w in (words, _("not current") if stale else "") if w)
        if said != self._said:
            self._said = said
            accessible.describe(self.value, f"{self.caption.get_text()}: {said}" if said else "")
        if stale != self.stale:
            self.stale = stale
            if stale:
                self.add_css_class("stale")
            else:
                self.remove_css_class("stale")
        if tooltip != self._tooltip:
            self._tooltip = tooltip
            if (tooltip is not None) != self.get_has_tooltip():
                self.set_has_tooltip(tooltip is not None)
            if self._pointer_in and self._tip is not None and tooltip:
                self._tip.set_text(tooltip)  # the tooltip on screen says it now, not at the next motion

    def get_tooltip_text(self) -> str | None:
        """The words the cell's tooltip shows (GTK's own tooltip text stays empty: they are given
        when it asks, :meth:`_answer_tooltip`)."""
        return self._tooltip

    def _answer_tooltip(self, _cell: Gtk.Widget, _x: int, _y: int, _keyboard: bool, tip: Gtk.Tooltip) -> bool:
        if not self._tooltip:
            return False
        tip.set_text(self._tooltip)
        self._tip = tip  # the display's one tooltip: while the pointer is in this cell, it is this cell's
        return True


class StatusToolbar(Gtk.ScrolledWindow):
    """One row of cells; the mode cell ellipsizes, then whole columns give way when the window is narrow.

    The row sits in a scrolled window without scroll bars so that it never sets the window's
    minimum width; :meth:`fit` then hides or shows columns so that what is shown fits.

    ``status_age()`` returns the seconds since the last status packet (the
    network side measures it: a robot standing still publishes no new values,
    so the model alone cannot tell fresh from old); None falls back to the time
    of the last value change.
    """

    def __init__(
        self,
        model: RobotModel,
        operator: OperatorState,
        *,
        clock: Callable[[], float] = time.monotonic,
        status_age: Callable[[], float | None] | None = None,
    ) -> None:
        super().__init__()
        self.model = model
        self.operator = operator
        self.clock = clock
        self.status_age = status_age
        self.row = Gtk.Box(orientation=Gtk.Orientation.HORIZONTAL, spacing=0)
        self.add_css_class("status-toolbar")
        self.set_can_focus(False)
        self.set_policy(Gtk.PolicyType.EXTERNAL, Gtk.PolicyType.NEVER)
        self.set_propagate_natural_height(True)
        self.set_child(self.row)
        self.battery_gauge = BatteryGauge()
        self.wifi_gauge = WifiGauge()
        self.cells: dict[str, Cell] = {
            "x": Cell(_("X m"), width_chars=6),
            "y": Cell(_("Y m"), width_chars=6),
            "th": Cell(_("Heading"), width_chars=5),
            "vel": Cell(_("mm/s"), width_chars=5),
            "rot": Cell(_("deg/s"), width_chars=4),
            "battery": Cell(_("Battery"), width_chars=6, gauge=self.battery_gauge),
            "wifi": Cell(_("Wi-Fi"), width_chars=5, gauge=self.wifi_gauge),
            "mode": Cell(_("Mode · status"), width_chars=6),
            "safe": Cell(_("Safe"), width_chars=3),
            "speed": Cell(_("Throttle"), width_chars=5),
            "link": Cell(_("Link: rtt, age/limit"), width_chars=14),
            "dock": Cell(_("Dock"), width_chars=9),
            "loc": Cell(_("Localization"), width_chars=9),
        }
        for cell in self.cells.values():
            self.row.append(cell)
        self.cells["dock"].set_visible(False)  # only for servers with dockInfo (LD robots)
        self.cells["loc"].set_visible(False)  # only for servers with getLocState (ARNL)
        self._loc_level: str | None = None
        self._loc_given_up = False
        """The Good localization column was hidden for width (it comes back with room, or news)."""
        mode = self.cells["mode"]
        mode.set_hexpand(True)
        mode.value.set_max_width_chars(40)  # the one column that takes the spare room
        self._fit_source = 0
        self._shown_at = -MOTION_REFRESH_S
        """When :meth:`refresh` last ran (``clock``)."""
        self._motion_due = 0
        """The timer that shows a pose still waiting once no status follows it (:data:`MOTION_REFRESH_S`)."""
        self._motion_at = 0.0
        self._motion_waits = False
        """A pose not shown yet: the next status at least :data:`MOTION_REFRESH_S` after the last
        refresh shows it, in the same frame as the map's (or the timer, if none comes)."""
        self.get_hadjustment().connect("changed", lambda _a: self._queue_fit())
        self._unobserve = [
            model.robot.observe(self._on_robot),
            # A new round trip or learned limit waits for the next second's tick (one relayout a
            # second at rest); a level or a ping unanswered shows at once.
            model.health.observe(self._on_health),
            model.connection.observe(lambda o, n: self.refresh()),
            operator.speed.observe(lambda o, n: self.refresh()),
            model.navigation.observe(lambda o, n: self.refresh()),
        ]
        self.refresh()

    def close(self) -> None:
        for remove in self._unobserve:
            remove()
        self._unobserve = []
        if self._fit_source:
            GLib.source_remove(self._fit_source)
            self._fit_source = 0
        if self._motion_due:
            GLib.source_remove(self._motion_due)
            self._motion_due = 0

    # -- width -------------------------------------------------------------------------------
    def _queue_fit(self) -> None:
        """The width changed (the adjustment follows every allocation): fit after this layout."""
        if not self._fit_source:
            self._fit_source = GLib.idle_add(self._fit_idle)

    def _fit_idle(self) -> bool:
        self._fit_source = 0
        for _round in range(2 * len(HIDE_FIRST)):  # measuring is immediate: settle in one go
            if not self.fit():
                break
        return False

    def _hideable(self) -> tuple[str, ...]:
        """HIDE_FIRST, after a Good localization column (a Lost one must stay in view)."""
        return ("loc", *HIDE_FIRST) if self._loc_level == "good" else HIDE_FIRST

    def fit(self) -> bool:
        """Hide or show one column so that the row fits; True if something changed (runs again)."""
        room = self.get_width()
        if room <= 0:
            return False
        need = self.row.measure(Gtk.Orientation.HORIZONTAL, -1)[0]
        order = self._hideable()
        if need > room:
            for name in order:
                if self.cells[name].get_visible():
                    self.cells[name].set_visible(False)
                    self._loc_given_up = self._loc_given_up or name == "loc"
                    return True
            return False
        hidden = [n for n in order if not self.cells[n].get_visible()]
        if hidden:
            cell = self.cells[hidden[-1]]
            cell.set_visible(True)
            if self.row.measure(Gtk.Orientation.HORIZONTAL, -1)[0] > room:
                cell.set_visible(False)  # still no room for it
                return False
            self._loc_given_up = self._loc_given_up and hidden[-1] != "loc"
            return True
        return False

    def hidden_columns(self) -> list[str]:
        """Columns given up for width (the dock column is absent, not given up, without dockInfo)."""
        return [n for n, c in self.cells.items() if not c.get_visible() and n not in ("dock", "loc")]

    def _on_robot(self, old: RobotState, new: RobotState) -> None:
        if _readings_only(old, new):  # a laser's or the sonar's new readings: nothing shown here
            return
        if self.clock() - self._shown_at >= MOTION_REFRESH_S or not _motion_only(old, new):
            self.refresh()  # (with the map's frame for the same status: one paint for both)
            return
        self._motion_waits, self._motion_at = True, self.clock()
        if not self._motion_due:  # the last pose of a drive shows even if no status follows it
            self._motion_due = GLib.timeout_add(round(2000 * MOTION_REFRESH_S), self._motion_refresh)

    def _motion_refresh(self) -> bool:
        if self._motion_waits and self.clock() - self._motion_at < MOTION_REFRESH_S:
            return True  # statuses still come: the next one shows it, with the map's frame
        self._motion_due = 0
        if self._motion_waits:
            self.refresh()
        return False

    def _on_health(self, old: LinkHealth, new: LinkHealth) -> None:
        if _health_news(old, new):
            self.refresh()

    def refresh(self) -> None:
        """Show the model's values and how old they are (called on changes and by the window's timer)."""
        now = self._shown_at = self.clock()
        self._motion_waits = False
        robot = self.model.robot.value
        conn: ConnectionState = self.model.connection.value
        health = self.model.health.value
        link_ok = conn.phase is Phase.CONNECTED and health.level is LinkLevel.OK
        age = self._age(now)
        have = age is not None
        stale = not have or not link_ok or (age is not None and age > STALE_AFTER)
        why = _stale_reason(have, age, conn, health.level)
        c = self.cells
        c["x"].show_value(number(robot.x / 1000, 2) if have else DASH, stale=stale, tooltip=why)
        c["y"].show_value(number(robot.y / 1000, 2) if have else DASH, stale=stale, tooltip=why)
        c["th"].show_value(heading_text(robot.th) if have else DASH, stale=stale, tooltip=why)
        c["vel"].show_value(number(robot.vel) if have else DASH, stale=stale, tooltip=why)
        c["rot"].show_value(number(robot.rot_vel) if have else DASH, stale=stale, tooltip=why)
        self._battery(robot, stale, why)
        self._wifi(robot, have and link_ok, why)
        strings_known = robot.strings_at is not None and (robot.mode or robot.status)
        mode = robot.mode if robot.status in ("", robot.mode) else f"{robot.mode} · {robot.status}"
        nav = self.model.navigation.value
        mode_tip = "\n".join([robot.extended_status or mode, *details_lines(robot, nav)])
        mode += goal_suffix(nav)
        if outcome_status(nav) and not nav.navigating:
            mode_tip += "\n" + _("Last navigation: {outcome}").format(outcome=outcome_status(nav))
        c["mode"].show_value(
            mode if strings_known else DASH,
            stale=not strings_known or not link_ok,
            tooltip=(why + "\n" if why and strings_known else "") + mode_tip if strings_known else why,
        )
        if robot.safe_drive is None:
            c["safe"].show_value(
                DASH, stale=True, tooltip=_("The server has not said whether safe drive is on")
            )
        else:
            c["safe"].show_value(_("On") if robot.safe_drive else _("OFF"), stale=not link_ok, tooltip=why)
            if robot.safe_drive:
                c["safe"].remove_css_class("alarm")
            else:
                c["safe"].add_css_class("alarm")
        c["speed"].show_value(
            _("{percent} %").format(percent=self.operator.speed.value.percent),
            stale=False,
            tooltip=_("+ / − to change"),
        )
        self._link(conn, health, age)
        self._dock(robot.dock_state, link_ok)
        self._loc(nav.loc_state, nav.loc_score, link_ok)

    def _loc(self, state: str | None, score: float | None, live: bool) -> None:
        """Localization (``getLocState``), shown only while the server offers it: good / poor / lost."""
        cell = self.cells["loc"]
        level = loc_level(state, score)
        if level != self._loc_level:
            self._loc_level = level
            self._loc_given_up = self._loc_given_up and level == "good"
            self._queue_fit()
        cell.set_visible(level is not None and not self._loc_given_up)
        for cls in ("good", "poor", "lost"):
            (cell.add_css_class if cls == level else cell.remove_css_class)(f"loc-{cls}")
        if level is not None:
            text = loc_text(state, score)
            tip = _("Localization: {state} (getLocState)").format(state=text)
            if level == "lost":
                tip += _(": the robot does not know where it is — Go to › Set robot position")
            cell.show_value(text, stale=not live, tooltip=tip, words=level)

    def _dock(self, state: str | None, live: bool) -> None:
        """The docking state, shown only while the server reports one (``dockInfo``)."""
        cell = self.cells["dock"]
        if state is None:
            cell.set_visible(False)
            return
        cell.set_visible(True)
        cell.show_value(
            state, stale=not live, tooltip=_("Docking state: {state} (dockInfo)").format(state=state)
        )

    def _age(self, now: float) -> float | None:
        numbers_at = self.model.robot.value.numbers_at
        if numbers_at is None:
            return None
        measured = self.status_age() if self.status_age is not None else None
        return max(0.0, measured if measured is not None else now - numbers_at)

    def _battery(self, robot, stale: bool, why: str | None) -> None:
        cell = self.cells["battery"]
        if robot.battery_v is None:
            cell.show_value(DASH, stale=True, tooltip=why or _("No battery reading"))
            self.battery_gauge.set_level(0.0, "unknown")
            return
        soc = robot.battery_is_soc
        text = (
            _("{percent} %").format(percent=number(robot.battery_v))
            if soc
            else _("{volts} V").format(volts=number(robot.battery_v, 1))
        )
        state = robot.battery_state
        levels = []
        if robot.battery_low is not None:
            low = _battery_value(robot.battery_low, soc)
            levels.append(_("low at {value}").format(value=low))
        if robot.battery_shutdown is not None:
            levels.append(_("shutdown at {value}").format(value=_battery_value(robot.battery_shutdown, soc)))
        tip = {"low": _("Battery LOW"), "critical": _("Battery at SHUTDOWN level")}.get(state, _("Battery"))
        tip += f" ({', '.join(levels)})" if levels else ""
        words = {"low": _("low"), "critical": _("at shutdown level")}.get(state, "")
        mark = "" if stale else {"low": _("LOW"), "critical": _("SHUTDOWN")}.get(state, "")
        cell.show_value(text, stale=stale, tooltip=(why + "\n" + tip) if why else tip, words=words, mark=mark)
        for cls in ("low", "critical"):
            if cls == state and not stale:
                cell.add_css_class(cls)
            else:
                cell.remove_css_class(cls)
        fraction = battery_fraction(robot.battery_v, robot.battery_shutdown, is_soc=robot.battery_is_soc)
        self.battery_gauge.set_level(fraction, "stale" if stale else state)

    def _wifi(self, robot, live: bool, why: str | None) -> None:
        cell = self.cells["wifi"]
        q, s = robot.wifi_quality, robot.wifi_signal
        if q is None and s is None:
            cell.show_value(
                DASH, stale=True, tooltip=_("The server does not publish Wi-Fi quality or signal")
            )
            self.wifi_gauge.set_bars(0, False)
            return
        text = _("{percent} %").format(percent=q) if q is not None else _("{dbm} dBm").format(dbm=s)
        parts = [
            _("quality {percent} %").format(percent=q) if q is not None else "",
            _("signal {dbm} dBm").format(dbm=s) if s is not None else "",
        ]
        tip = _("Wi-Fi {readings}").format(readings=", ".join(p for p in parts if p))
        cell.show_value(text, stale=not live, tooltip=(why + "\n" + tip) if why and not live else tip)
        self.wifi_gauge.set_bars(wifi_bars(q, s), live)

    def _link(self, conn: ConnectionState, health, age: float | None) -> None:
        cell = self.cells["link"]
        if conn.phase is not Phase.CONNECTED:
            text = (
                phase_word(conn.phase)
                if conn.phase in (Phase.CONNECTING, Phase.RECONNECTING)
                else level_word(LinkLevel.DOWN)
            )
            cell.show_value(
                text,
                stale=True,
                tooltip=_("Not connected ({phase})").format(phase=phase_word(conn.phase)),
                words=_("not connected"),
            )
            cell.show_level(f"link-{LinkLevel.DOWN.value}")
            return
        rtt = (
            DASH
            if health.rtt_ms is None
            else _("{ms} ms").format(ms=number(health.rtt_ms, 1 if health.rtt_ms < 10 else 0))
        )
        age_shown = DASH if age is None else age_text(age)
        tip = _(
            "Link {level}: round trip {rtt}, last status {age} ago, {dropped} bad packets dropped"
        ).format(level=level_word(health.level), rtt=rtt, age=age_shown, dropped=health.dropped)
        text = f"{rtt} {age_shown}"
        if health.stale_limit is not None:  # the learned limit next to the age it is compared with
            text = f"{rtt} {DASH if age is None else number(age, 1)}/{number(health.stale_limit, 2)}"
            tip += "\n" + _(
                "Stale after {limit} s without status: learned from this link's jitter ({jitter} ms), "
                "at most {ceiling} s"
            ).format(
                limit=number(health.stale_limit, 2),
                jitter=number(health.jitter_ms or 0),
                ceiling=number(STATUS_CEILING, 2),
            )
        if health.ping_failures > 0:
            # The link may look alive (status still arriving) while the server no longer hears us.
            text = _("no ping ×{count}").format(count=health.ping_failures)
            tip = (
                ngettext(
                    "Server not answering pings ({count} in a row): it may not hear our commands; "
                    "driving is stopped",
                    "Server not answering pings ({count} in a row): it may not hear our commands; "
                    "driving is stopped",
                    health.ping_failures,
                ).format(count=health.ping_failures)
                + "\n"
                + tip
            )
        cell.show_value(
            text,
            stale=health.level is not LinkLevel.OK or health.ping_failures > 0,
            tooltip=tip,
            words=_("link {level}").format(level=level_word(health.level)),
            mark="" if health.level is LinkLevel.OK else level_word(health.level).upper(),
        )
        cell.show_level(f"link-{health.level.value}")


def _readings_only(old: RobotState, new: RobotState) -> bool:
    """Whether only the range readings differ (a driving robot's laser and sonar: 10 changes a second
    the toolbar does not show, each a refresh of a dozen cells)."""
    return (old.sonar, old.laser) != (new.sonar, new.laser) and replace(
        new, sonar=old.sonar, laser=old.laser
    ) == old


_MOTION_FIELDS = ("x", "y", "th", "vel", "rot_vel", "lat_vel", "sonar", "laser")


def _motion_only(old: RobotState, new: RobotState) -> bool:
    """Whether only the pose, the speeds and the range readings differ (a robot driving along)."""
    return replace(new, **{f: getattr(old, f) for f in _MOTION_FIELDS}) == old


def _health_news(old: LinkHealth, new: LinkHealth) -> bool:
    """Whether a link health change must show before the next tick: its level or unanswered pings."""
    return old.level is not new.level or old.ping_failures != new.ping_failures


def _battery_value(value: float, soc: bool) -> str:
    """A battery threshold with its unit: a charge in per cent or a voltage."""
    return (
        _("{percent} %").format(percent=number(value))
        if soc
        else _("{volts} V").format(volts=number(value, 1))
    )


def _stale_reason(have: bool, age: float | None, conn: ConnectionState, level: LinkLevel) -> str | None:
    if conn.phase is not Phase.CONNECTED:
        return (
            _("Not connected: the last known values ({phase})").format(phase=phase_word(conn.phase))
            if have
            else _("Not connected")
        )
    if not have:
        return _("No status from the robot yet")
    if level is not LinkLevel.OK:
        return (
            _("Link {level}: no fresh status for {age}").format(level=level_word(level), age=age_text(age))
            if age is not None
            else _("Link {level}").format(level=level_word(level))
        )
    if age is not None and age > STALE_AFTER:
        return _("No update for {age}").format(age=age_text(age))
    return None

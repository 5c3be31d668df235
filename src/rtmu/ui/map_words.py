"""The map in words: what a screen reader says for the drawn map, and when it says it again.

The map is a drawing; a screen reader user hears its accessible description instead: where the robot
is, its mode, its battery and what it is doing. The words are rounded (half a metre, 15 degrees, a
tenth of a volt, whole metres left) so the description — and the announcement a screen reader makes
when it changes — follows material changes, not every 10 Hz status packet.
"""

from __future__ import annotations

from collections.abc import Callable

from ..base.i18n import _
from ..base.i18n import number as i18n_number
from ..model.observables import ConnectionState, NavState, Phase, RobotModel, RobotState
from .nav_text import loc_level, where
from .state_words import phase_word

POSE_STEP_M = 0.5
HEADING_STEP_DEG = 15


def _step(value: float, step: float) -> float:
    return round(value / step) * step


def battery_words(robot: RobotState) -> str:
    """``battery 12.8 volts, low``: the number and the state its colour shows."""
    if robot.battery_v is None:
        return _("battery unknown")
    number = (
        _("{battery_v} percent").format(battery_v=i18n_number(robot.battery_v))
        if robot.battery_is_soc
        else _("{battery_v} volts").format(battery_v=i18n_number(robot.battery_v, 1))
    )
    state = {"low": _(", low"), "critical": _(", at shutdown level")}.get(robot.battery_state, "")
    return _("battery {number}{state}").format(number=number, state=state)


def activity_words(robot: RobotState, nav: NavState) -> str:
    """What the robot is doing, in words: going somewhere, driving, or standing."""
    if nav.navigating:
        left = (
            ""
            if nav.remaining_mm is None
            else _(", {value} metres left").format(value=i18n_number(nav.remaining_mm / 1000))
        )
        return (
            _("going home") if nav.target == "home" else _("going to {where}").format(where=where(nav.target))
        ) + left
    if abs(robot.vel) > 20 or abs(robot.rot_vel) > 3:
        return "moving"
    return _("standing still")


def map_description(robot: RobotState, nav: NavState, connection: ConnectionState) -> str:
    """The map's accessible description (see the module notes)."""
    if connection.phase is not Phase.CONNECTED:
        return _("Not connected ({value})").format(value=phase_word(connection.phase))
    if robot.numbers_at is None:
        return _("Connected, no position from the robot yet")
    x, y = _step(robot.x / 1000, POSE_STEP_M), _step(robot.y / 1000, POSE_STEP_M)
    heading = int(_step(robot.th, HEADING_STEP_DEG)) % 360
    parts = [
        _("Robot at x {x}, y {y} metres, heading {heading} degrees").format(
            x=i18n_number(x, 1), y=i18n_number(y, 1), heading=heading
        )
    ]
    mode = robot.mode or robot.status
    if mode:
        parts.append(_("mode {mode}").format(mode=mode))  # the server's own word
    parts.append(battery_words(robot))
    parts.append(activity_words(robot, nav))
    level = loc_level(nav.loc_state, nav.loc_score)
    if level is not None:
        parts.append(_("localization {level}").format(level=level))
    return "; ".join(parts)


def _said_of(robot: RobotState, nav: NavState, connection: ConnectionState) -> tuple[object, ...]:
    """Everything :func:`map_description` reads, rounded as it rounds: equal tuples, equal words."""
    return (
        connection.phase,
        robot.numbers_at is None,
        _step(robot.x / 1000, POSE_STEP_M),
        _step(robot.y / 1000, POSE_STEP_M),
        int(_step(robot.th, HEADING_STEP_DEG)) % 360,
        robot.mode or robot.status,
        robot.battery_v,
        robot.battery_is_soc,
        robot.battery_state,
        abs(robot.vel) > 20 or abs(robot.rot_vel) > 3,
        nav,
    )


class MapDescription:
    """Keeps ``describe(text)`` (the map widget's description) in step with the model, only on change."""

    def __init__(self, model: RobotModel, describe: Callable[[str], None]) -> None:
        self.model = model
        self._describe = describe
        self.text = ""
        self._said: tuple[object, ...] | None = None
        self._unobserve = [
            model.robot.observe(self._changed),
            model.navigation.observe(self._changed),
            model.connection.observe(self._changed),
        ]
        self._changed(None, None)

    def _changed(self, _old: object, _new: object) -> None:
        m = self.model
        robot, nav, connection = m.robot.value, m.navigation.value, m.connection.value
        said = _said_of(robot, nav, connection)
        if said == self._said:
            return  # nothing the words say changed (a status a second restates a pose, ten while driving)
        self._said = said
        text = map_description(robot, nav, connection)
        if text != self.text:
            self.text = text
            self._describe(text)

    def close(self) -> None:
        for remove in self._unobserve:
            remove()
        self._unobserve = []

"""What the controller learns from the robot's motion: its limits, and how each jog ended (GTK-free).

One object per controller, fed the robot's updates: the robot's top speed and braking
(``motion_limits``: read once per connection from its server's configuration where it lists them,
raised by any faster speed seen while a lease drives) and the jog in progress (``jog_watch``), whose
outcome is said once through ``say``. ``changed`` is called when the limits change, so a drive in
progress takes a new near-people throttle at once.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ..base.i18n import N_
from ..base.notices import Kind, Notice
from ..client.config_feed import VERSIONS as CONFIG_DATA
from ..client.lease import DriveRatios
from ..values.intents import FetchConfig, Intent, MoveDistance, TurnBy
from ..values.state import RobotState
from .jog_watch import JogWatch
from .motion_limits import RobotLimits, limits_from_config

LIMITS_TIMEOUT = 15.0
"""Seconds the robot's limits may take to come from its configuration (else the assumed ones stay)."""


class MotionWatch:
    """See the module notes. ``link`` may offer ``send`` and ``run_blocking`` (the runner does)."""

    def __init__(
        self,
        link: Any,
        say: Callable[[Notice], None],
        changed: Callable[[], None],
        clock: Callable[[], float],
    ) -> None:
        self.link = link
        self._say = say
        self._changed = changed
        self._clock = clock
        self.limits = RobotLimits()
        self.jogs = JogWatch()
        self._connection = 0
        """Counts connections: limits fetched for an earlier one are not taken."""

    def connected(self, supports: Callable[[str], bool], *, ask: bool = True) -> None:
        """A new connection: assumed limits until its server says its own (fetched off the UI thread
        when ``ask``)."""
        self._connection += 1
        self.limits = RobotLimits()
        if not ask:
            return
        send = getattr(self.link, "send", None)
        run_blocking = getattr(self.link, "run_blocking", None)
        if send is None or run_blocking is None or not any(supports(n) for n in CONFIG_DATA):
            return
        future, connection = send(FetchConfig()), self._connection

        def fetched(config: object) -> None:
            if config is not None and connection == self._connection:
                self.limits = limits_from_config(config)  # type: ignore[arg-type]
                self._changed()

        run_blocking(lambda: future.result(timeout=LIMITS_TIMEOUT), fetched)

    def disconnected(self) -> None:
        self._connection += 1
        self.jogs.jog = None  # the link's banner speaks for a jog cut off

    def robot_changed(self, robot: RobotState, driving: DriveRatios | None) -> None:
        """The robot's latest state; ``driving``: the ratios of a lease in force, if any."""
        if driving is not None:
            seen = self.limits.seen(robot.vel, driving.trans, driving.throttle)
            if seen is not self.limits:
                self.limits = seen
                self._changed()
        self._say_outcome(self.jogs.update(robot, self._clock()))

    def _say_outcome(self, outcome: str | None) -> None:
        if outcome is not None:
            short = not outcome.startswith(("Went", "Turned"))
            self._say((Notice.warning if short else Notice.info)(Kind.NAVIGATION, outcome))

    def tick(self, robot: RobotState) -> None:
        """The UI's timer: a robot standing still sends the same numbers, which change nothing in the
        model, so the jog's end is also looked for here."""
        if self.jogs.jog is not None:
            self._say_outcome(self.jogs.update(robot, self._clock()))

    def intent_sent(self, intent: Intent, robot: RobotState) -> None:
        """An intent that moves the robot went out: a jog is watched from here; anything else ends one."""
        if isinstance(intent, TurnBy | MoveDistance):
            self.end_jog(N_("another jog"), robot)
            kind, amount = ("turn", intent.degrees) if isinstance(intent, TurnBy) else ("move", intent.mm)
            self.jogs.start(kind, float(amount), robot, self._clock())
        else:
            self.end_jog(intent.label, robot)

    def end_jog(self, why: str, robot: RobotState) -> None:
        said = self.jogs.end(why, robot)
        if said is not None:
            self._say(Notice.info(Kind.NAVIGATION, said))

"""The window session's share of navigation: the typed :class:`~rtmu.values.state.NavState` and its notices.

:class:`NavFeed` is fed by :class:`~rtmu.client.session.Session`: every robot update (the status
string and mode name say whether the server navigates, and how it ended — see
:mod:`~rtmu.client.nav_status`), ``getPath`` and ``getLocState`` packets, and the goal list. It
publishes a new ``NavState`` only when it changed, and one ``Kind.NAVIGATION`` notice per outcome
("Arrived at Lab B", "Failed to get to Lab B because the robot is lost", "Docked"). What the
session asks for is its subscription table; this class only reads what arrives.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Coroutine
from dataclasses import replace
from typing import Any

from ..base.notices import Kind, Notice
from ..protocol.errors import ProtocolError
from ..protocol.payloads import Payload
from ..protocol.payloads.map import Goals
from ..protocol.payloads.navigation import GotoPose, LocalizationState, LocState, PlannedPath
from ..values.state import NavChanged, NavOutcome, NavState, RobotState
from .connection import AriaClient, Packet
from .errors import ClientError
from .nav_status import MAX_TEXT, NAV_DATA, NavPhase, NavReading, path_remaining, read_status

MAX_GOALS = 10_000
"""Goal names kept from one ``getGoals`` (a hostile list is cut, not kept whole)."""

Publish = Callable[[NavChanged], None]
NoticeFn = Callable[[Notice], None]
Decode = Callable[[str, bytes], Any]
Spawn = Callable[[Coroutine[Any, Any, None], str], None]
GoalPose = Callable[[str], tuple[float, float, float | None] | None]
"""The map's pose of a goal by name (None when the map has no such goal, or no map is loaded)."""


class NavFeed:
    """Navigation state for one session (network loop only); ``changed()`` hears navigating start/stop."""

    def __init__(
        self,
        publish: Publish,
        notice: NoticeFn,
        decode: Decode,
        spawn: Spawn,
        reply_timeout: float,
        goal_pose: GoalPose = lambda name: None,
    ) -> None:
        self._publish = publish
        self._notice = notice
        self._decode = decode
        self._spawn = spawn
        self._timeout = reply_timeout
        self._goal_pose = goal_pose
        self.changed: Callable[[], None] = lambda: None
        """Called when ``navigating`` flips (the session then starts or ends ``getPath``)."""
        self.state = NavState()
        self._history = True
        """No status seen yet on this connection: an outcome read now happened before we came."""
        self._last: NavReading | None = None
        self._last_dock: str | None = None
        self._sent_pose: tuple[float, float, float | None] | None = None
        self._pose = (0.0, 0.0)

    @property
    def navigating(self) -> bool:
        return self.state.navigating

    # -- connection --------------------------------------------------------------------------
    def connected(self, client: AriaClient) -> None:
        """A fresh login: forget the last server's navigation, note what this one lists."""
        self._reset(NavState(offered=frozenset(n for n in NAV_DATA if client.supports(n))))

    def disconnected(self) -> None:
        self._reset(NavState())

    def _reset(self, state: NavState) -> None:
        was = self.state.navigating
        self._history, self._last, self._last_dock, self._sent_pose = True, None, None, None
        self._set(state)
        if was:
            self.changed()

    def _set(self, state: NavState) -> None:
        if state != self.state:
            self.state = state
            self._publish(NavChanged(state))

    def _update(self, **changes: Any) -> None:
        self._set(replace(self.state, **changes))

    # -- what we asked for -------------------------------------------------------------------
    def sent(self, payload: Payload) -> None:
        """We sent a navigation command: remember the point, for ``target_pose`` ("Going to point")."""
        if isinstance(payload, GotoPose):
            th = None if payload.th is None else float(payload.th)
            self._sent_pose = (float(payload.x), float(payload.y), th)

    # -- robot updates (status, mode, pose) ----------------------------------------------------
    def robot(self, robot: RobotState) -> None:
        """Called with every new robot value: the words decide the phase, the pose the distance left."""
        self._pose = (robot.x, robot.y)
        reading = read_status(robot.status, robot.mode_name)
        if robot.status and (reading != self._last or robot.dock_state != self._last_dock):
            self._read(reading, robot.dock_state)
            self._last, self._last_dock = reading, robot.dock_state
            self._history = False
        elif self.state.navigating and self.state.path:
            self._update(remaining_mm=path_remaining(robot.x, robot.y, self.state.path))

    def _read(self, reading: NavReading, dock_state: str | None) -> None:
        was = self.state.navigating
        if reading.phase is NavPhase.IDLE and dock_state in ("Docking", "Docked"):
            # An LD robot's dock reports through dockInfo, not through ARNL's words.
            phase = NavPhase.GOING if dock_state == "Docking" else NavPhase.DOCKED
            reading = NavReading(phase, "dock", text=dock_state)
        if reading.phase is NavPhase.GOING:
            target = reading.target
            pose = self._sent_pose if target == "point" else self._goal_pose(target)
            self._update(
                navigating=True,
                target=target,
                target_pose=pose,
                outcome=NavOutcome.NONE,
                outcome_text="",
                reason="",
            )
        elif reading.finished:
            outcome = {
                NavPhase.ARRIVED: NavOutcome.ARRIVED,
                NavPhase.DOCKED: NavOutcome.DOCKED,
                NavPhase.FAILED: NavOutcome.FAILED,
            }[reading.phase]
            news = was or self._last is None or reading.text != self._last.text
            self._update(
                navigating=False,
                target=reading.target or self.state.target,
                path=(),
                remaining_mm=None,
                outcome=outcome,
                outcome_text=reading.text,
                reason=reading.reason,
            )
            if news and not self._history:
                sentence = reading.sentence()[:MAX_TEXT]
                if outcome is NavOutcome.FAILED:
                    self._notice(Notice.warning(Kind.NAVIGATION, sentence))
                else:
                    self._notice(Notice.info(Kind.NAVIGATION, sentence))
        elif was:
            self._update(
                navigating=False,
                path=(),
                remaining_mm=None,
                outcome=NavOutcome.CANCELLED,
                outcome_text=reading.text,
                reason="",
            )
        if self.state.navigating != was:
            self.changed()

    # -- packets -----------------------------------------------------------------------------
    def on_path(self, packet: Packet) -> None:
        path = self._decode(packet.name, packet.payload)
        if not isinstance(path, PlannedPath) or not self.state.navigating:
            return
        x, y = self._pose
        self._update(path=path.points, remaining_mm=path_remaining(x, y, path.points))

    def on_loc_state(self, packet: Packet) -> None:
        loc = self._decode(packet.name, packet.payload)
        if not isinstance(loc, LocState):
            return
        was = self.state.loc_state
        label = loc.state_label
        self._update(loc_state=label, loc_score=round(loc.score_fraction, 3))
        if label == LocalizationState.LOST.label and was is not None and was != label:
            self._notice(
                Notice.warning(Kind.NAVIGATION, "The robot is lost: localize it before sending it anywhere")
            )

    def on_goals_updated(self, client: AriaClient) -> None:
        self._spawn(self.fetch_goals(client), "nav-goals")

    async def fetch_goals(self, client: AriaClient) -> None:
        """The map's goal names (``getGoals``), where listed; a failed answer keeps the old list."""
        if not client.supports("getGoals"):
            return
        with contextlib.suppress(ClientError, ProtocolError):
            reply = await client.request_once("getGoals", timeout=self._timeout)
            goals = self._decode("getGoals", reply.payload)
            if isinstance(goals, Goals):
                self._update(goals=tuple(g[:MAX_TEXT] for g in goals.goals[:MAX_GOALS]))

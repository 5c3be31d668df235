"""The window session's share of navigation: the typed :class:`~rtmu.values.state.NavState` and its notices.

:class:`NavFeed` hears every robot update (the status
string and mode name say whether the server navigates, and how it ended — see
:mod:`~rtmu.client.nav_status`), ``getPath`` and ``getLocState`` packets, and the goal list. It
publishes a new ``NavState`` only when it changed, and one ``Kind.NAVIGATION`` notice per outcome
("Arrived at Lab B", "Failed to get to Lab B because the robot is lost", "Docked"). What the
server is asked for is its subscription table; it carries out the navigation intents.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterable
from dataclasses import replace
from typing import Any, ClassVar

from ..base.i18n import _
from ..base.notices import Kind, Notice
from ..protocol.errors import ProtocolError
from ..protocol.payloads import Payload
from ..protocol.payloads.ld import GotoRouteGoal
from ..protocol.payloads.map import Goals
from ..protocol.payloads.navigation import Dock as DockPayload
from ..protocol.payloads.navigation import GotoGoal as GotoGoalPayload
from ..protocol.payloads.navigation import GotoPose as GotoPosePayload
from ..protocol.payloads.navigation import Home, LocalizationState, LocalizeToPose, LocState, PlannedPath
from ..protocol.payloads.navigation import TourGoals as TourGoalsPayload
from ..values.intents import Dock, GoHome, GotoGoal, GotoPose, Intent, Localize, TourGoals
from ..values.state import NavChanged, NavOutcome, NavState, RobotState
from .call_values import Packet
from .connection import AriaClient
from .errors import ClientError
from .feed import Feed, FeedContext
from .map_feed import goal_pose
from .nav_status import MAX_TEXT, NAV_DATA, NavReading, path_remaining, read_motion
from .subscriptions import Subscription

MAX_GOALS = 10_000
"""Goal names kept from one ``getGoals`` (a hostile list is cut, not kept whole)."""
SENDS: dict[type[Intent], str] = {
    GotoGoal: "gotoGoal",
    GotoPose: "gotoPose",
    GoHome: "home",
    Dock: "dock",
    TourGoals: "tourGoals",
    Localize: "localizeToPose",
}


class NavFeed(Feed):
    """Navigation state for one session (network loop only): the goals, the path, the outcome."""

    handles: ClassVar[tuple[type[Intent], ...]] = tuple(SENDS)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self.state = NavState()
        self._history = True
        """No status seen yet on this connection: an outcome read now happened before we came."""
        self._last: NavReading | None = None
        self._sent_pose: tuple[float, float, float | None] | None = None
        self._pose = (0.0, 0.0)

    def subscriptions(self, client: AriaClient) -> Iterable[Subscription]:
        config = self.ctx.config
        return (
            Subscription("getLocState", config.loc_state_interval_ms, self.on_loc_state),
            Subscription("goalsUpdated", -1, self._on_goals_updated, needs="getGoals"),
            Subscription(
                "getPath", config.path_interval_ms, self.on_path, only_while=lambda: self.navigating
            ),
        )

    def changed(self) -> None:
        """``navigating`` flipped: the session starts or ends ``getPath``."""
        self.ctx.sync_subscriptions()

    # -- intents: the server drives ------------------------------------------------------------
    def handle(self, intent: Intent) -> None:
        """Send a navigation command; an LD robot without ``gotoGoal`` reaches a goal by ``gotoRouteGoal``."""
        name = SENDS[type(intent)]
        client = self.ctx.client
        if (
            isinstance(intent, GotoGoal)
            and client is not None
            and (not client.supports(name) or (intent.route and client.supports("gotoRouteGoal")))
        ):
            name = "gotoRouteGoal"
        client = self.require(name)
        payload = _payload(intent)
        if isinstance(payload, GotoPosePayload):
            th = None if payload.th is None else float(payload.th)
            self._sent_pose = (float(payload.x), float(payload.y), th)
        if name == "gotoRouteGoal" and isinstance(intent, GotoGoal):
            client.send(GotoRouteGoal(intent.name))
        else:
            client.send(payload)

    @property
    def navigating(self) -> bool:
        return self.state.navigating

    # -- connection --------------------------------------------------------------------------
    def connected(self, client: AriaClient) -> None:
        """A fresh login: forget the last server's navigation, note what this one lists, read the goals."""
        self._reset(NavState(offered=frozenset(n for n in NAV_DATA if client.supports(n))))
        self.ctx.spawn(self.fetch_goals(client), "nav-goals")

    def disconnected(self) -> None:
        self._reset(NavState())

    def _reset(self, state: NavState) -> None:
        was = self.state.navigating
        self._history, self._last, self._sent_pose = True, None, None
        self._set(state)
        if was:
            self.changed()

    def _set(self, state: NavState) -> None:
        if state != self.state:
            self.state = state
            self.ctx.publish(NavChanged(state))

    def _update(self, **changes: Any) -> None:
        self._set(replace(self.state, **changes))

    def robot_reports(self, **changes: float | None) -> None:
        """What an LD robot reports of itself (``DataStore_*``): its localization score and distance to
        the goal, into the same fields ARNL's requests fill."""
        self._update(**changes)

    # -- robot updates (status, mode, pose) ----------------------------------------------------
    def robot_changed(self, robot: RobotState) -> None:
        """Called with every new robot value: the words decide the phase, the pose the distance left."""
        self._pose = (robot.x, robot.y)
        reading = read_motion(robot.status, robot.mode_name, robot.dock_state)
        if robot.status and reading != self._last:
            self._read(reading)
            self._last = reading
            self._history = False
        elif self.state.navigating and self.state.path:
            self._update(remaining_mm=path_remaining(robot.x, robot.y, self.state.path))

    def _read(self, reading: NavReading) -> None:
        was = self.state.navigating
        if reading.phase is NavOutcome.GOING:
            target = reading.target
            pose = self._sent_pose if target == "point" else goal_pose(self.ctx.map, target)
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
                NavOutcome.ARRIVED: NavOutcome.ARRIVED,
                NavOutcome.DOCKED: NavOutcome.DOCKED,
                NavOutcome.FAILED: NavOutcome.FAILED,
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
                sentence = reading.sentence()
                if len(sentence) > MAX_TEXT:  # a short one keeps its Said: the window says it translated
                    sentence = sentence[:MAX_TEXT]
                if outcome is NavOutcome.FAILED:
                    self.ctx.notice(Notice.warning(Kind.NAVIGATION, sentence))
                else:
                    self.ctx.notice(Notice.info(Kind.NAVIGATION, sentence))
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
        path = self.ctx.decode(packet.name, packet.payload)
        if not isinstance(path, PlannedPath) or not self.state.navigating:
            return
        x, y = self._pose
        self._update(path=path.points, remaining_mm=path_remaining(x, y, path.points))

    def on_loc_state(self, packet: Packet) -> None:
        loc = self.ctx.decode(packet.name, packet.payload)
        if not isinstance(loc, LocState):
            return
        was = self.state.loc_state
        label = loc.state_label
        self._update(loc_state=label, loc_score=round(loc.score_fraction, 3))
        if label == LocalizationState.LOST.label and was is not None and was != label:
            self.ctx.notice(
                Notice.warning(
                    Kind.NAVIGATION, _("The robot is lost: localize it before sending it anywhere")
                )
            )

    def _on_goals_updated(self, packet: Packet) -> None:
        client = self.ctx.client
        if client is not None:
            self.ctx.spawn(self.fetch_goals(client), "nav-goals")

    async def fetch_goals(self, client: AriaClient) -> None:
        """The map's goal names (``getGoals``), where listed; a failed answer keeps the old list."""
        if not client.supports("getGoals"):
            return
        with contextlib.suppress(ClientError, ProtocolError):
            reply = await client.request_once("getGoals", timeout=self.ctx.config.reply_timeout)
            goals = self.ctx.decode("getGoals", reply.payload)
            if isinstance(goals, Goals):
                self._update(goals=tuple(g[:MAX_TEXT] for g in goals.goals[:MAX_GOALS]))


def _payload(intent: Intent) -> Payload:
    """The wire payload of a navigation intent (headings and points rounded to whole mm and degrees)."""
    if isinstance(intent, GotoGoal):
        return GotoGoalPayload(intent.name)
    if isinstance(intent, GotoPose):
        return GotoPosePayload(
            round(intent.x), round(intent.y), None if intent.th is None else round(intent.th)
        )
    if isinstance(intent, Localize):
        return LocalizeToPose(round(intent.x), round(intent.y), round(intent.th))
    return {GoHome: Home, Dock: DockPayload, TourGoals: TourGoalsPayload}[type(intent)]()

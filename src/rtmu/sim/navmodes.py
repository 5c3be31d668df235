"""ARNL's navigation modes as the simulator plays them: ``Goto`` (goals, points, home, tours) and ``dock``.

Mode names, mode strings and status texts are ARNL's (``ArServerModeGoto``, ``ArServerModeDock``):
``Going to <goal>`` / ``Arrived at <goal>`` / ``Failed to plan to <goal>`` / ``Failed to get to <goal>
(<why>)`` and ``… because robot lost``; ``Going to point``, ``Returning home`` / ``Returned home``,
``Touring to <goal>``; ``Going to dock at <dock>``, ``Driving into dock``, ``Docked``, ``Undocking``,
``Unable to dock``, ``Cannot drive to dock at <dock>``, ``Failed dock``. What the path planner says
(``pathPlannerStatus``, and the ``(<why>)`` part) is in our own words, ARNL's being in its closed library.

Like ARNL's, the dock mode locks itself while the robot is not undocked and unlocks when asked: a drive
command then makes it back out first, and the mode that asked takes over once the robot is free.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from rtmu.mapfile import MapObject
from rtmu.protocol.payloads.ld import DockState
from rtmu.protocol.payloads.navigation import LocalizationState

from . import p3dx
from .follower import Follower, Progress
from .modes import Mode
from .planner import GridCache, NoPath, Plan, PlanGrid
from .robot import Body, Command, normalize_deg

REPLANS_BEFORE_GIVING_UP = 4
DOCK_APPROACH_MM = 600.0
"""The planner takes the robot this far in front of the dock; it drives the rest straight in."""
DOCK_CREEP_SPEED = 100.0
UNDOCK_DISTANCE_MM = 600.0
CHARGE_V_PER_S = 1.5 / 3600.0
"""Docked, the pack gains 1.5 V an hour (on top of the idle drain): a flat pack is full in about an hour."""
LOCALIZE_SECONDS = 0.5
GOOD_SCORE = 0.95
LOST_SCORE = 0.08


@dataclass
class NavMap:
    """What navigation needs of the served map: goals and docks by name, home, and its planning grid."""

    key: object
    segments: np.ndarray
    points: np.ndarray
    objects: tuple[MapObject, ...] = ()
    home: tuple[float, float, float] = (0.0, 0.0, 0.0)
    grids: GridCache = field(default_factory=GridCache)

    def goals(self) -> list[MapObject]:
        return [o for o in self.objects if o.is_goal]

    def goal(self, name: str) -> MapObject | None:
        """The goal called ``name``, compared case-insensitively as ARIA's map does (exact first)."""
        goals = self.goals()
        return next((o for o in goals if o.name == name), None) or next(
            (o for o in goals if o.name.casefold() == name.casefold()), None
        )

    def docks(self) -> list[MapObject]:
        return [o for o in self.objects if o.type.lower() == "dock" or o.type.lower() == "dockwithheading"]

    def grid(self) -> PlanGrid:
        return self.grids.get(self.key, lambda: PlanGrid(self.segments, self.points, self.objects))


@dataclass
class Localization:
    """ARNL's localization as ``getLocState`` reports it: a state and a score (0–1)."""

    state: LocalizationState = LocalizationState.GOOD
    score: float = GOOD_SCORE
    since: float = 0.0

    @property
    def lost(self) -> bool:
        return self.state is LocalizationState.LOST

    def lose(self, now: float) -> None:
        self.state, self.score, self.since = LocalizationState.LOST, LOST_SCORE, now

    def start(self, now: float) -> None:
        self.state, self.score, self.since = LocalizationState.INITIALIZING, 0.0, now

    def tick(self, now: float) -> None:
        if self.state is LocalizationState.INITIALIZING and now - self.since >= LOCALIZE_SECONDS:
            self.state, self.score = LocalizationState.GOOD, GOOD_SCORE


class _Flags(Protocol):
    mode_info: bool
    dock_info: bool


class World(Protocol):
    """What the navigation modes use of the world (the world owns them; this keeps the import one-way)."""

    body: Body
    time: float
    mode: Mode
    nav_map: NavMap | None
    localization: Localization

    @property
    def changes(self) -> _Flags: ...

    def activate(self, mode: Mode) -> None: ...

    def check_strings(self) -> None: ...

    def sonar(self) -> list[tuple[int, int]]: ...

    def home_pose(self) -> tuple[float, float, float | None]: ...


class PathTask:
    """ARNL's path-planning task, shared by both modes: one plan, its follower, and what to say about it."""

    def __init__(self, world: World) -> None:
        self.world = world
        self.follower: Follower | None = None
        self.status = "No goal"
        self.failure = ""
        self._goal: tuple[float, float] = (0.0, 0.0)
        self._replans = 0
        self.replans = 0
        """Plans made again on the way (around what the sonar saw, or after straying), ever."""

    def start(self, goal: tuple[float, float], heading: float | None) -> bool:
        self.cancel()
        self._goal, self._replans = goal, 0
        nav = self.world.nav_map
        if nav is None:
            return self._fail_plan("no map")
        body = self.world.body
        try:
            plan = nav.grid().plan((body.x, body.y), goal)
        except NoPath as exc:
            return self._fail_plan(exc.reason)
        self.follower = Follower(plan, heading)
        self.status = "Moving to goal"
        return True

    def _fail_plan(self, reason: str) -> bool:
        self.status = self.failure = f"Failed to plan: {reason}"
        return False

    def cancel(self) -> None:
        self.follower = None
        self.status = "No goal"

    def step(self, body: Body, now: float) -> tuple[Command, Progress | None]:
        """The next command; ``Progress.BLOCKED`` only once replanning around the obstacle has failed."""
        follower = self.follower
        if follower is None:
            return Command(0.0, 0.0), None
        cmd, progress = follower.step(body, self.world.sonar(), now)
        if progress is Progress.ARRIVED:
            self.follower = None
            self.status = "Goal reached"
        elif progress in (Progress.BLOCKED, Progress.OFF_PATH):
            return self._replan(body, progress)
        elif follower.limited_by_sonar:
            self.status = "Slowing for an obstacle"
        else:
            self.status = "Moving to goal"
        return cmd, progress

    def _replan(self, body: Body, why: Progress) -> tuple[Command, Progress | None]:
        follower, nav = self.follower, self.world.nav_map
        assert follower is not None and nav is not None
        self._replans += 1
        self.replans += 1
        seen = np.asarray(self.world.sonar(), dtype=np.float64).reshape(-1, 2)
        if why is Progress.BLOCKED and len(seen):
            near = np.hypot(seen[:, 0] - body.x, seen[:, 1] - body.y) < 2000.0
            seen = seen[near]
        try:
            if self._replans > REPLANS_BEFORE_GIVING_UP:
                raise NoPath("path blocked")
            extra = seen if why is Progress.BLOCKED else None
            plan: Plan = nav.grid().plan((body.x, body.y), self._goal, extra)
        except NoPath as exc:
            self.follower = None
            reason = "path blocked" if why is Progress.BLOCKED else exc.reason
            self.status = self.failure = f"Failed to reach goal: {reason}"
            return Command(0.0, 0.0), Progress.BLOCKED
        self.follower = Follower(plan, follower.heading)
        self.status = "Planning around an obstacle"
        return Command(0.0, 0.0), Progress.MOVING

    def path(self) -> list[tuple[int, int]]:
        return [] if self.follower is None else self.follower.remaining()

    def distance_left(self) -> float:
        b = self.world.body
        return 0.0 if self.follower is None else self.follower.distance_left(b.x, b.y)


class GotoMode(Mode):
    """ARNL's ``ArServerModeGoto``: mode name ``Goto``; shown as ``Goto goal``, ``Goto point``, ``Go home``
    or ``Touring goals``."""

    NAME = "Goto"
    DATA = ("gotoGoal", "gotoPose", "home", "tourGoals")

    def __init__(self, world: World, path_task: PathTask) -> None:
        super().__init__()
        self.world = world
        self.path_task = path_task
        self.goal_name = ""
        self._mode = "Goto goal"
        self._target: tuple[float, float, float | None] = (0.0, 0.0, None)
        self._home = False
        self._touring = False
        self._tour_only: tuple[str, ...] | None = None
        """A route's goals (an LD robot's patrol), or None: every goal of the map."""
        self.done = True

    @property
    def mode_string(self) -> str:
        return self._mode

    # -- requests (each activates the mode, as ARNL's do) ----------------------------------
    def goto_goal(self, name: str) -> None:
        self._reset("Goto goal")
        self.goal_name = name
        self.status = f"Going to {name}"
        self._begin()

    def goto_point(self, x: float, y: float, th: float | None) -> None:
        self._reset("Goto point")
        self._target = (x, y, th)
        self.status = "Going to point"
        self._begin()

    def home(self) -> None:
        self._reset("Go home")
        self._home = True
        self._target = self.world.home_pose()
        self.status = "Returning home"
        self._begin()

    def tour(self, only: tuple[str, ...] | None = None) -> None:
        """Goal after goal, for ever: every goal of the map, or only these (a route, in its order)."""
        current = self.goal_name
        self._reset("Touring goals")
        self.goal_name = current
        self._touring = True
        self._tour_only = only
        self._begin()

    def _reset(self, mode: str) -> None:
        self._mode, self._home, self._touring, self.goal_name = mode, False, False, ""
        self._tour_only = None

    def _begin(self) -> None:
        """(Re)start in this mode: activating again when already active re-plans, as ARNL's ``activate``."""
        if self.world.mode is self:
            self.activate(self.world.body, self.world.time)
        else:
            self.world.activate(self)
        self.world.check_strings()  # the new status goes out now, not at the next cycle

    # -- the mode -------------------------------------------------------------------------
    def activate(self, body: Body, now: float) -> None:
        self.done = False
        if self._touring:
            self._plan_next_tour_goal()
            return
        if self.world.nav_map is None:
            self.status, self.done = "Failed driving because map empty", True
            return
        if self.world.localization.lost:
            self._lost()
            return
        if self.goal_name:
            goal = self.world.nav_map.goal(self.goal_name) if self.world.nav_map else None
            if goal is None or not self._plan_to_goal(goal):
                self.status = f"Failed to plan to {self.goal_name}"
                self.done = True
        else:
            x, y, th = self._target
            if not self.path_task.start((x, y), th):
                self.status = "Failed to plan to point"
                self.done = True

    def deactivate(self) -> None:
        self.path_task.cancel()
        self.done = True

    def _plan_to_goal(self, goal: MapObject) -> bool:
        heading = goal.th if goal.type.lower() == "goalwithheading" else None
        return self.path_task.start((goal.x, goal.y), heading)

    def _plan_next_tour_goal(self) -> None:
        nav = self.world.nav_map
        goals = [] if nav is None else nav.goals()
        if self._tour_only is not None:
            by_name = {g.name: g for g in goals}
            goals = [by_name[name] for name in self._tour_only if name in by_name]
        if self.world.localization.lost:
            self.status, self.done = "Failed touring because robot lost", True
            return
        names = [g.name for g in goals]
        start = names.index(self.goal_name) + 1 if self.goal_name in names else 0
        for k in range(len(goals)):
            goal = goals[(start + k) % len(goals)]
            self.goal_name = goal.name
            self.status = f"Touring to {goal.name}"
            if self._plan_to_goal(goal):
                return
        self.status, self.done = "Failed touring goals: All goals failed.", True

    def command(self, body: Body, now: float, dt: float) -> Command:
        if self.done:
            return Command(0.0, 0.0)
        if self.world.localization.lost:
            self._lost()
            return Command(0.0, 0.0)
        cmd, progress = self.path_task.step(body, now)
        if progress is Progress.ARRIVED:
            self._arrived()
        elif progress is Progress.BLOCKED:
            self._failed(f" ({self.path_task.failure.removeprefix('Failed to reach goal: ')})")
        return cmd

    def _arrived(self) -> None:
        if self._home:
            self.status, self.done = "Returned home", True
        elif self._touring:
            self._plan_next_tour_goal()
        elif self.goal_name:
            self.status, self.done = f"Arrived at {self.goal_name}", True
        else:
            self.status, self.done = "Arrived at point", True

    def _failed(self, why: str) -> None:
        if self._touring:
            self._plan_next_tour_goal()
            return
        self.path_task.cancel()
        self.done = True
        if self._home:
            self.status = "Failed to get home" + why
        elif self.goal_name:
            self.status = f"Failed to get to {self.goal_name}" + why
        else:
            self.status = "Failed to get to point" + why

    def _lost(self) -> None:
        self.path_task.cancel()
        self.path_task.status = "Robot lost"
        self.done = True
        if self._touring:
            self.status = "Failed touring because robot lost"
        elif self._home:
            self.status = "Failed to get home because robot lost"
        elif self.goal_name:
            self.status = f"Failed to get to {self.goal_name} because robot lost"
        else:
            self.status = "Failed to get to point because robot lost"


class DockMode(Mode):
    """ARNL's ``ArServerModeDock``: mode name ``dock``, shown as ``Dock``; charges while docked."""

    NAME = "dock"
    MODE_STRING = "Dock"
    DATA = ("dock", "undock")

    def __init__(self, world: World, path_task: PathTask) -> None:
        super().__init__()
        self.world = world
        self.path_task = path_task
        self.state = DockState.UNDOCKED
        self.dock_name = ""
        self._dock: MapObject | None = None
        self._phase = ""
        self._back_from: tuple[float, float] = (0.0, 0.0)
        self.status = "Stopped"

    @property
    def locked(self) -> bool:
        return self.state is not DockState.UNDOCKED

    @property
    def will_unlock(self) -> bool:
        return True

    @property
    def docked(self) -> bool:
        return self.state is DockState.DOCKED

    def _switch(self, state: DockState) -> None:
        if state is not self.state:
            self.state = state
            self.world.changes.dock_info = True
            self.world.changes.mode_info = True

    def activate(self, body: Body, now: float) -> None:
        if self.state is DockState.DOCKED:
            return
        nav = self.world.nav_map
        docks = [] if nav is None else nav.docks()
        if not docks:
            self.status = "Unable to dock"
            self._switch(DockState.UNDOCKED)
            return
        dock = min(docks, key=lambda d: math.hypot(d.x - body.x, d.y - body.y))
        self._dock, self.dock_name = dock, dock.name
        ax, ay = self._approach(dock)
        if self.world.localization.lost or not self.path_task.start((ax, ay), dock.th):
            self.status = f"Cannot drive to dock at {dock.name}"
            self._switch(DockState.UNDOCKED)
            return
        self.status = f"Going to dock at {dock.name}"
        self._phase = "approach"
        self._switch(DockState.DOCKING)

    def deactivate(self) -> None:
        self.path_task.cancel()

    def leave(self) -> None:
        """The simulator took the robot away (its pose was reset): not docked, nothing under way."""
        self.path_task.cancel()
        self.status = "Stopped"
        self._switch(DockState.UNDOCKED)

    def request_unlock(self) -> None:
        """Someone else wants the robot: back out of the dock (or stop going there)."""
        if self.state is DockState.DOCKED:
            self.status = "Undocking"
            self._back_from = (self.world.body.x, self.world.body.y)
            self._switch(DockState.UNDOCKING)
        elif self.state is DockState.DOCKING:
            self.path_task.cancel()
            self.status = "Stopped"
            self._switch(DockState.UNDOCKED)

    def command(self, body: Body, now: float, dt: float) -> Command:
        if self.state is DockState.DOCKING:
            return self._docking(body, now)
        if self.state is DockState.UNDOCKING:
            if math.hypot(body.x - self._back_from[0], body.y - self._back_from[1]) >= UNDOCK_DISTANCE_MM:
                self.status = "Stopped"
                self._switch(DockState.UNDOCKED)
                return Command(0.0, 0.0)
            return Command(-DOCK_CREEP_SPEED * 2, 0.0, safe=False)
        return Command(0.0, 0.0)

    def _docking(self, body: Body, now: float) -> Command:
        if self.world.localization.lost:
            return self._fail()
        if self._phase == "approach":
            cmd, progress = self.path_task.step(body, now)
            if progress is Progress.BLOCKED:
                return self._fail()
            if progress is Progress.ARRIVED:
                self._phase = "drive in"
                self.status = "Driving into dock"
            return cmd
        dock = self._dock
        assert dock is not None
        left = math.hypot(dock.x - body.x, dock.y - body.y)
        if left <= 20.0 or self._past(dock, body):
            if body.is_stopped():
                self.status = "Docked"
                self._switch(DockState.DOCKED)
            return Command(0.0, 0.0)
        err = normalize_deg(math.degrees(math.atan2(dock.y - body.y, dock.x - body.x)) - body.th)
        speed = min(DOCK_CREEP_SPEED, math.sqrt(2.0 * p3dx.TRANS_DECEL * 0.5 * left))
        return Command(speed if abs(err) < 20 else 0.0, max(-20.0, min(20.0, 2.0 * err)), safe=False)

    @staticmethod
    def _past(dock: MapObject, body: Body) -> bool:
        th = math.radians(dock.th)
        return (body.x - dock.x) * math.cos(th) + (body.y - dock.y) * math.sin(th) > 0.0

    def _fail(self) -> Command:
        self.path_task.cancel()
        self.status = "Failed dock"
        self._switch(DockState.UNDOCKED)
        return Command(0.0, 0.0)

    @staticmethod
    def _approach(dock: MapObject) -> tuple[float, float]:
        th = math.radians(dock.th)
        return (dock.x - DOCK_APPROACH_MM * math.cos(th), dock.y - DOCK_APPROACH_MM * math.sin(th))


def charge(world: World, dt: float) -> None:
    """A docked robot's pack charges (the body's own drain still applies)."""
    body = world.body
    body.battery_v = min(body.battery_v + CHARGE_V_PER_S * dt, p3dx.BATTERY_FULL_V)

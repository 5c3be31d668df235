"""The navigation data an ARNL server offers, for the simulator's profiles (``ROWS`` + ``HANDLERS``).

Goals, points, home and tours go to the ``Goto`` mode, ``dock``/``undock`` to the ``dock`` mode (see
:mod:`rtmu.sim.navmodes`); ``localizeToPose`` puts the robot where the operator says, as ARNL does with
MobileSim; ``getLocState``, ``getPath``, ``pathPlannerStatus`` and ``goalName`` report. ARNL's ``dockInfo`` is
left out: RTMU takes it for the mark of an LD robot (the aram profile serves it), and the status
strings already say ``Docked``.
``SimulatorLoseLocalization`` is the simulator's own: the robot is lost until it is localized again.
Descriptions are our own words; names, argument layouts, groups and flags are ARNL's.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from rtmu.protocol.errors import FieldUnderrun, PayloadError
from rtmu.protocol.payloads.navigation import (
    LOC_SCORE_FULL,
    MAX_PATH_POINTS,
    GoalName,
    GotoGoal,
    GotoPose,
    LocalizeToPose,
    LocState,
    PathPlannerStatus,
    PlannedPath,
)

from .catalogue import Row
from .handlers import Call, Handler, Reply


def _args(cls, call: Call):
    """The request's arguments, or None when they do not decode (ignored, as ARIA ignores bad packets)."""
    try:
        return cls.decode(call.args)
    except (FieldUnderrun, PayloadError, ValueError):
        return None


def _goto_goal(call: Call) -> Iterable[Reply]:
    args = _args(GotoGoal, call)
    if args is not None:
        call.world.touch()
        call.world.goto_mode.goto_goal(args.goal)
    return ()


def _goto_pose(call: Call) -> Iterable[Reply]:
    args = _args(GotoPose, call)
    if args is not None:
        call.world.touch()
        call.world.goto_mode.goto_point(
            float(args.x), float(args.y), None if args.th is None else float(args.th)
        )
    return ()


def _home(call: Call) -> Iterable[Reply]:
    call.world.touch()
    call.world.goto_mode.home()
    return ()


def _tour_goals(call: Call) -> Iterable[Reply]:
    call.world.touch()
    call.world.goto_mode.tour()
    return ()


def _dock(call: Call) -> Iterable[Reply]:
    world, mode = call.world, call.world.dock_mode
    if world.mode is mode:
        world.touch()
        if not mode.locked:  # active but undocked (it failed, or backed out): try again
            mode.activate(world.body, world.time)
    else:
        world.activate(mode)
    world.check_strings()
    return ()


def _undock(call: Call) -> Iterable[Reply]:
    world = call.world
    world.touch()
    if world.mode is world.dock_mode:
        world.dock_mode.request_unlock()
    return ()


def _localize(call: Call) -> Iterable[Reply]:
    args = _args(LocalizeToPose, call)
    if args is not None:
        call.world.localize_to(float(args.x), float(args.y), float(args.th))
    return ()


def _loc_state(call: Call) -> Iterable[Reply]:
    loc = call.world.localization
    return (LocState(int(loc.state), round(loc.score * LOC_SCORE_FULL)).encode(),)


def _path(call: Call) -> Iterable[Reply]:
    points = call.world.path_task.path()
    if len(points) > MAX_PATH_POINTS:  # never for a smoothed plan; thin rather than refuse
        step = math.ceil(len(points) / MAX_PATH_POINTS)
        points = points[::step][: MAX_PATH_POINTS - 1] + points[-1:]
    return (PlannedPath(tuple(points)).encode(),)


def _planner_status(call: Call) -> Iterable[Reply]:
    return (PathPlannerStatus(call.world.path_task.status).encode(),)


def _goal_name(call: Call) -> Iterable[Reply]:
    return (GoalName(call.world.goto_mode.goal_name).encode(),)


def _lose_localization(call: Call) -> Iterable[Reply]:
    call.world.lose_localization()
    return ()


NAV = "Navigation"
NAV_INFO = "NavigationInfo"
ROWS: tuple[Row, ...] = (
    ("gotoGoal", "Drives the robot to a goal of the map", "string: goal name", "none", NAV, "RETURN_NONE"),
    (
        "gotoPose",
        "Drives the robot to a point of the map, and turns it to a heading if one is given",
        "byte4: x (mm); byte4: y (mm); optional byte4: heading (degrees)",
        "none",
        NAV,
        "RETURN_NONE",
    ),
    ("home", "Drives the robot back to its home", "none", "none", NAV, "RETURN_NONE"),
    ("tourGoals", "Drives the robot from goal to goal of the map", "none", "none", NAV, "RETURN_NONE"),
    ("goalName", "The goal being driven to", "none", "string: goal name", NAV, "RETURN_SINGLE"),
    (
        "pathPlannerStatus",
        "What the path planner is doing, or why it failed",
        "none",
        "string: status",
        NAV,
        "RETURN_SINGLE",
    ),
    (
        "getPath",
        "The path the robot is following, as the corners still ahead of it",
        "none",
        "byte2: number of points; then per point byte4: x, byte4: y (mm)",
        NAV_INFO,
        "RETURN_SINGLE",
    ),
    (
        "dock",
        "Drives the robot to its charger and docks",
        "optional ubyte: 1 docking forced",
        "none",
        NAV,
        "RETURN_NONE",
    ),
    ("undock", "Backs the robot out of its charger", "none", "none", NAV, "RETURN_NONE"),
    (
        "localizeToPose",
        "Tells the robot where it is on the map",
        "byte4: x (mm); byte4: y (mm); byte4: heading (degrees); "
        "optional ubyte4: xy spread, ubyte4: heading spread",
        "none",
        "Localize",
        "RETURN_NONE",
    ),
    (
        "getLocState",
        "How sure the robot is of where it is",
        "none",
        "ubyte: 0 localized, 1 idle, 2 lost, 3 localizing; ubyte2: score x 1000 (0 lost, 1000 certain)",
        NAV_INFO,
        "RETURN_SINGLE",
    ),
    (
        "SimulatorLoseLocalization",
        "Makes the simulated robot lose track of where it is (navigation fails until it is localized again)",
        "none",
        "none",
        "CustomCommands",
        "RETURN_NONE",
    ),
)

HANDLERS: dict[str, Handler] = {
    "gotoGoal": _goto_goal,
    "gotoPose": _goto_pose,
    "home": _home,
    "tourGoals": _tour_goals,
    "goalName": _goal_name,
    "pathPlannerStatus": _planner_status,
    "getPath": _path,
    "dock": _dock,
    "undock": _undock,
    "localizeToPose": _localize,
    "getLocState": _loc_state,
    "SimulatorLoseLocalization": _lose_localization,
}

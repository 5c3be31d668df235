"""The data an Omron LD robot offers beyond serverDemo, for ``rtmu sim --kind aram``.

A data module of the profile extension point (:mod:`rtmu.sim.profiles`): ``ROWS`` for the catalogue
and ``HANDLERS`` for the server. Two lasers seen from the world's walls by the same ray caster as
the sonar, one ray per degree; docking by the simulator's ``dock`` mode (it drives to the dock,
``dockInfo`` reports its state, and a drive backs out of it first), a few routes that ``patrol``
tours goal after goal (a route is goals of the map: :func:`route_goals`), ``gotoRouteGoal`` driving
to a goal, ``DataStore_*`` strings from the simulator's real values (under names 6MTX robots list;
the value texts are ours) and ``say`` (recorded). LD's configuration data are listed but never
answered (:data:`CONFIG_API`: their layouts are not public, and a made-up answer would teach RTMU a
layout no robot has). What was asked is kept per server in :func:`ld_state` so tests can look.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from rtmu.protocol.errors import FieldUnderrun, PayloadError
from rtmu.protocol.payloads.drawings import Drawing, DrawingList, DrawingListPacket
from rtmu.protocol.payloads.ld import (
    DataStoreValue,
    DockInfo,
    GotoRouteGoal,
    Patrol,
    Routes,
    Say,
)
from rtmu.protocol.payloads.sensors import RangeDeviceReadings

from .catalogue import Row
from .handlers import Call, Handler, Reply

if TYPE_CHECKING:
    from .context import SimHost

LASERS: dict[str, tuple[float, int, float]] = {
    "Laser_1Current": (250.0, 240, 15_000.0),
    "Laser_2Current": (200.0, 126, 4_000.0),
}
"""Data name → (mm ahead of the centre, field of view in degrees, range in mm): an LD90's main
safety laser and its low front laser, as public LD bridges configure them."""
LASER_DRAWINGS = (
    Drawing("Laser_1Current", "polyDots", 0x0000FF, 60, 75, 200, 0x000000, "DefaultOn"),
    Drawing("Laser_2Current", "polyDots", 0x0000C0, 60, 75, 200, 0x000000, "DefaultOn"),
)
ROUTES = ("Loop", "Kitchen run", "Night patrol")
SAY_LIMIT = 100
"""Texts kept in :attr:`LdState.said` (the oldest go first)."""


@dataclass
class LdState:
    patrols: list[str] = field(default_factory=list)
    route_goals: list[str] = field(default_factory=list)
    """Goals asked for with ``gotoRouteGoal`` (each also driven to)."""
    said: list[str] = field(default_factory=list)


_STATES: weakref.WeakKeyDictionary[SimHost, LdState] = weakref.WeakKeyDictionary()


def ld_state(server: SimHost) -> LdState:
    """This server's LD state (created on first use)."""
    state = _STATES.get(server)
    if state is None:
        state = _STATES[server] = LdState()
    return state


# -- laser -----------------------------------------------------------------------------------
def laser_points(call: Call, name: str) -> tuple[tuple[int, int], ...]:
    """Global (x, y) mm of each hit within range, one ray per degree over the laser's field."""
    body = call.world.body
    offset, field_deg, max_range = LASERS[name]
    th = math.radians(body.th)
    ox = body.x + offset * math.cos(th)
    oy = body.y + offset * math.sin(th)
    half = math.radians(field_deg / 2)
    angles = th + np.linspace(-half, half, field_deg + 1)
    ranges = call.world.obstacles.cast(ox, oy, angles, max_range)
    hit = np.isfinite(ranges)
    xs = np.rint(ox + ranges[hit] * np.cos(angles[hit])).astype(int)
    ys = np.rint(oy + ranges[hit] * np.sin(angles[hit])).astype(int)
    return tuple(zip(xs.tolist(), ys.tolist(), strict=True))


def _laser(call: Call) -> Iterable[Reply]:
    name = call.name
    return (call.server.cycle_cached(name, lambda: RangeDeviceReadings(laser_points(call, name)).encode()),)


def _drawing_list(call: Call) -> Iterable[Reply]:
    packets = [DrawingListPacket(d).encode() for d in LASER_DRAWINGS]  # LD robots list no sonar
    return (*packets, DrawingListPacket(None).encode())


def _list_drawings(call: Call) -> Iterable[Reply]:
    return (DrawingList(LASER_DRAWINGS).encode(),)


# -- docking: the simulator's dock mode drives; LD robots report it as dockInfo -----------------------
def _dock_info(call: Call) -> Iterable[Reply]:
    return (DockInfo(call.world.dock_mode.state).encode(),)


# -- routes and speech ---------------------------------------------------------------------------
def _routes(call: Call) -> Iterable[Reply]:
    return (Routes(ROUTES).encode(),)


def _patrol(call: Call) -> Iterable[Reply]:
    try:
        route = Patrol.decode(call.args).route
    except (FieldUnderrun, PayloadError, ValueError):
        return ()
    if route in ROUTES:
        ld_state(call.server).patrols.append(route)
        world = call.world
        names = tuple(g.name for g in world.nav_map.goals()) if world.nav_map is not None else ()
        world.touch()
        world.goto_mode.tour(route_goals(route, names))
    return ()


def route_goals(route: str, goals: tuple[str, ...]) -> tuple[str, ...]:
    """The goals a route visits, in order: the loop every goal, the kitchen run every other one,
    the night patrol every goal backwards (the simulator's routes are made from the map's goals)."""
    if route == ROUTES[1]:
        return goals[::2]
    if route == ROUTES[2]:
        return goals[::-1]
    return goals


def _goto_route_goal(call: Call) -> Iterable[Reply]:
    try:
        goal = GotoRouteGoal.decode(call.args).goal
    except (FieldUnderrun, PayloadError, ValueError):
        return ()
    ld_state(call.server).route_goals.append(goal)
    call.world.touch()
    call.world.goto_mode.goto_goal(goal)
    return ()


def _say(call: Call) -> Iterable[Reply]:
    try:
        text = Say.decode(call.args).text
    except (FieldUnderrun, PayloadError, ValueError):
        return ()
    said = ld_state(call.server).said
    said.append(text)
    del said[:-SAY_LIMIT]
    return ()


# -- data store --------------------------------------------------------------------------------
def _closest_obstacle_mm(call: Call) -> float:
    body = call.world.body
    points = laser_points(call, "Laser_1Current") + laser_points(call, "Laser_2Current")
    if not points:
        return math.inf
    return min(math.hypot(x - body.x, y - body.y) for x, y in points)


DATA_STORE: dict[str, tuple[str, object]] = {
    "DataStore_LaserLocalizationScore": (
        "Localization score (0–100)",
        lambda call: str(round(call.world.localization.score * 100)),
    ),
    "DataStore_WirelessQuality": ("Wi-Fi link quality (0–70)", lambda call: str(call.world.wifi().quality)),
    "DataStore_Distance_to_goal": (
        "Distance to the goal in mm (0: no goal)",
        lambda call: str(round(call.world.path_task.distance_left())),
    ),
    "DataStore_Closest_Obstacle_Distance": (
        "Distance to the closest obstacle in mm",
        lambda call: (lambda d: "none" if d == math.inf else str(round(d)))(_closest_obstacle_mm(call)),
    ),
    "DataStore_DockingState": (
        "Docking state",
        lambda call: DockInfo(call.world.dock_mode.state).state_label,
    ),
}
"""Names as 6MTX robots list them; descriptions and value texts are the simulator's own (LD's are
not public)."""
CONFIG_API: tuple[Row, ...] = tuple(
    (name, f"{what} (LD configuration; layout not public)", "not public", "not public", "ConfigEditing", "")
    for name, what in (
        ("getConfigValues", "The configuration's values"),
        ("setConfigValues", "Sets configuration values"),
        ("updateConfigValues", "Changes configuration values"),
        ("configExpandedSectionList", "The configuration's sections"),
    )
)
"""LD's configuration data, listed as a 6MTX robot lists them and never answered here."""


def _data_store(call: Call) -> Iterable[Reply]:
    entry = DATA_STORE.get(call.name)
    if entry is None:
        return ()
    value = entry[1](call)  # type: ignore[operator]
    return (DataStoreValue(str(value)).encode(),)


ROWS: tuple[Row, ...] = (
    (
        "Laser_1Current",
        "",
        "none",
        "byte4: count, then byte4: x, byte4: y per point (mm)",
        "SensorInfo",
        "RETURN_SINGLE",
    ),
    (
        "Laser_2Current",
        "",
        "none",
        "byte4: count, then byte4: x, byte4: y per point (mm)",
        "SensorInfo",
        "RETURN_SINGLE",
    ),
    ("dock", "Sends the robot to its dock", "none", "none", "Navigation", "RETURN_NONE"),
    ("undock", "Undocks the robot", "none", "none", "Navigation", "RETURN_NONE"),
    (
        "dockInfo",
        "The docking state",
        "none",
        "ubyte: 0 undocked, 1 docking, 2 docked, 3 undocking; ubyte: 1 docking forced; "
        "ubyte2: seconds to shutdown (0 none)",
        "NavigationInfo",
        "RETURN_SINGLE",
    ),
    (
        "dockInfoChanged",
        "Broadcast when the docking state changes",
        "none",
        "as dockInfo",
        "NavigationInfo",
        "RETURN_SINGLE",
    ),
    (
        "getRoutes",
        "The routes of the map",
        "none",
        "string: route name, repeated",
        "Navigation",
        "RETURN_SINGLE",
    ),
    ("routesUpdated", "Broadcast when the routes change", "none", "none", "Navigation", "RETURN_NONE"),
    ("patrol", "Patrols a route", "string: route name", "none", "Navigation", "RETURN_NONE"),
    (
        "gotoRouteGoal",
        "Drives to a goal of the route",
        "string: goal name",
        "none",
        "Navigation",
        "RETURN_NONE",
    ),
    ("say", "Speaks a text", "string: text", "none", "Audio", "RETURN_NONE"),
    *(
        (name, desc, "none", "string: value", "DataStore", "RETURN_SINGLE")
        for name, (desc, _) in DATA_STORE.items()
    ),
    *CONFIG_API,
)

HANDLERS: dict[str, Handler] = {
    "Laser_1Current": _laser,
    "Laser_2Current": _laser,
    "getDrawingList": _drawing_list,
    "listDrawings": _list_drawings,
    "dockInfo": _dock_info,
    "getRoutes": _routes,
    "patrol": _patrol,
    "gotoRouteGoal": _goto_route_goal,
    "say": _say,
    **dict.fromkeys(DATA_STORE, _data_store),
}

"""Asking an LD (ARAM) server for its extra data, only where its data list names it.

Shared by the CLI (``rtmu routes`` / ``patrol`` / ``say`` / ``status``) and the window's session:
every function checks :meth:`AriaClient.supports` first and answers None / empty when the server
does not list the data, so a serverDemo-like server is never asked for any of it.
"""

from __future__ import annotations

import re

from ..base.i18n import N_, Said
from ..protocol.payloads.ld import (
    DATA_STORE_PREFIX,
    DataStoreValue,
    DockInfo,
    GotoRouteGoal,
    Patrol,
    Routes,
    Say,
)
from ..protocol.payloads.map import Goals
from .connection import AriaClient
from .errors import MalformedReply, NotSupported

LASER_NAMES = ("Laser_1Current", "Laser_2Current")
"""The LD range devices RTMU draws, when listed."""
MAX_LASERS = 8
_LASER_DRAWING = re.compile(r"(?!sonar)\w+_\d+Current", re.IGNORECASE)
"""ARIA names a laser ``<kind>_<n>`` (its laser connector: ``sim_lms2xx_1``, ``lms1xx_1``, ``urg_1``;
ARAM: ``Laser_1``) and the drawing of its current readings ``<name>Current``; the sonar, bumpers and
IRs have names of their own (``sonarCurrent``, ``bumpersCurrent``, ``irsCurrent``)."""


def laser_names(client: AriaClient) -> tuple[str, ...]:
    """The lasers' current-readings data the server lists (an LD robot's and an ARIA/Pioneer one's)."""
    listed = [e.name for e in client.datalist if _LASER_DRAWING.fullmatch(e.name)]
    return tuple(dict.fromkeys([*LASER_NAMES, *sorted(listed)]))[: len(LASER_NAMES) + MAX_LASERS]


async def dock_info(client: AriaClient, timeout: float) -> DockInfo | None:
    """The docking state, or None when the server has no ``dockInfo``."""
    if not client.supports("dockInfo"):
        return None
    info = (await client.request_once("dockInfo", timeout=timeout)).decode()
    if not isinstance(info, DockInfo):
        raise MalformedReply(Said(N_("dockInfo did not decode as a docking state")))
    return info


async def routes(client: AriaClient, timeout: float) -> tuple[str, ...]:
    """The server's route names (``getRoutes``); NotSupported when it has none."""
    if not client.supports("getRoutes"):
        raise NotSupported("getRoutes", Said(N_("this server offers no routes (getRoutes)")))
    reply = (await client.request_once("getRoutes", timeout=timeout)).decode()
    if not isinstance(reply, Routes):
        raise MalformedReply(Said(N_("getRoutes did not decode as route names")))
    return reply.routes


async def goals(client: AriaClient, timeout: float) -> tuple[str, ...]:
    """The map's goal names (``getGoals``); NotSupported when the server lists none."""
    if not client.supports("getGoals"):
        raise NotSupported("getGoals", Said(N_("this server offers no goal list (getGoals)")))
    reply = (await client.request_once("getGoals", timeout=timeout)).decode()
    if not isinstance(reply, Goals):
        raise MalformedReply(Said(N_("getGoals did not decode as goal names")))
    return reply.goals


def goto_route_goal(client: AriaClient, goal: str) -> None:
    """Drive to ``goal`` (LD robots); NotSupported when the server has no ``gotoRouteGoal``."""
    if not client.supports("gotoRouteGoal"):
        said = Said(N_("this server cannot drive to route goals (gotoRouteGoal)"))
        raise NotSupported("gotoRouteGoal", said)
    client.send(GotoRouteGoal(goal))


def patrol(client: AriaClient, route: str) -> None:
    """Start patrolling ``route``; NotSupported when the server has no ``patrol``."""
    if not client.supports("patrol"):
        raise NotSupported("patrol", Said(N_("this server cannot patrol routes (patrol)")))
    client.send(Patrol(route))


def say(client: AriaClient, text: str) -> None:
    """Have the robot speak ``text``; NotSupported when the server has no ``say``."""
    if not client.supports("say"):
        raise NotSupported("say", Said(N_("this server cannot speak (say)")))
    client.send(Say(text))


def data_store_names(client: AriaClient) -> list[str]:
    """Every ``DataStore_*`` data the server lists, sorted."""
    return sorted(e.name for e in client.datalist if e.name.startswith(DATA_STORE_PREFIX))


async def data_store(client: AriaClient, timeout: float) -> dict[str, str]:
    """Every listed ``DataStore_*`` value, by data name (a value that does not decode is left out)."""
    out: dict[str, str] = {}
    for name in data_store_names(client):
        try:
            value = (await client.request_once(name, timeout=timeout)).decode()
        except MalformedReply:
            continue
        if isinstance(value, DataStoreValue):
            out[name] = value.value
    return out


_SCALE = re.compile(r"\(\s*0\s*[-–]\s*(\d+)\s*\)")
"""A range in a data list description, e.g. "Wi-Fi link quality (0–70)"."""


NAV_FIELDS = frozenset({"loc_score", "remaining_mm"})
"""Of :func:`store_fields`' keys, those that are :class:`~rtmu.values.state.NavState`'s (the one
localization score and the one distance to the goal, whichever server reports them)."""


def store_fields(name: str, value: str, description: str = "") -> dict[str, float | None]:
    """The state fields a ``DataStore_*`` value gives the toolbar (:data:`NAV_FIELDS` are navigation's).

    Names as 6MTX robots list them (``DataStore_LaserLocalizationScore``,
    ``DataStore_WirelessQuality``, ``DataStore_Distance_to_goal``,
    ``DataStore_Closest_Obstacle_Distance``), read without case or underscores so that spellings such
    as ``DataStore_Localization_Score`` or ``DataStore_WiFi_Quality`` count too; anything else only
    goes to the details table. Wi-Fi quality becomes % using the range in its description ("(0–70)":
    Linux's link quality), else it is taken as % already. A value that is not a number clears the field.
    """
    key = name.lower().replace("_", "").replace("-", "")
    try:
        number: float | None = float(value.split()[0])
    except (ValueError, IndexError):
        number = None
    if "localizationscore" in key or "localisationscore" in key:
        return {"loc_score": None if number is None else round(max(0.0, min(100.0, number)) / 100, 3)}
    if "wifiquality" in key or "wirelessquality" in key:
        if number is None:
            return {"wifi_quality": None}
        top = _SCALE.search(description)
        scale = int(top.group(1)) if top and int(top.group(1)) > 0 else 100
        return {"wifi_quality": round(max(0.0, min(100.0, number * 100 / scale)))}
    if "distancetogoal" in key:
        return {"remaining_mm": None if number is None or number <= 0 else round(number)}  # 0: no goal
    if "closestobstacle" in key:
        return {"closest_obstacle_mm": None if number is None else max(0, round(number))}
    return {}

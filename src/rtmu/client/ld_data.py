"""Asking an LD (ARAM) server for its extra data, only where its data list names it.

Shared by the CLI (``rtmu routes`` / ``patrol`` / ``say`` / ``status``) and the window's session:
every function checks :meth:`AriaClient.supports` first and answers None / empty when the server
does not list the data, so a serverDemo-like server is never asked for any of it.
"""

from __future__ import annotations

from ..protocol.payloads.ld import DATA_STORE_PREFIX, DataStoreValue, DockInfo, Patrol, Routes, Say
from .connection import AriaClient
from .errors import MalformedReply, NotSupported

LASER_NAMES = ("Laser_1Current", "Laser_2Current")
"""The LD range devices RTMU draws, when listed."""


async def dock_info(client: AriaClient, timeout: float) -> DockInfo | None:
    """The docking state, or None when the server has no ``dockInfo``."""
    if not client.supports("dockInfo"):
        return None
    info = (await client.request_once("dockInfo", timeout=timeout)).decode()
    if not isinstance(info, DockInfo):
        raise MalformedReply("dockInfo did not decode as a docking state")
    return info


async def routes(client: AriaClient, timeout: float) -> tuple[str, ...]:
    """The server's route names (``getRoutes``); NotSupported when it has none."""
    if not client.supports("getRoutes"):
        raise NotSupported("getRoutes", "this server offers no routes (getRoutes)")
    reply = (await client.request_once("getRoutes", timeout=timeout)).decode()
    if not isinstance(reply, Routes):
        raise MalformedReply("getRoutes did not decode as route names")
    return reply.routes


def patrol(client: AriaClient, route: str) -> None:
    """Start patrolling ``route``; NotSupported when the server has no ``patrol``."""
    if not client.supports("patrol"):
        raise NotSupported("patrol", "this server cannot patrol routes (patrol)")
    client.send("patrol", Patrol(route))


def say(client: AriaClient, text: str) -> None:
    """Have the robot speak ``text``; NotSupported when the server has no ``say``."""
    if not client.supports("say"):
        raise NotSupported("say", "this server cannot speak (say)")
    client.send("say", Say(text))


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

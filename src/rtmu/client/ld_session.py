"""The window session's share of LD (ARAM) data: lasers, docking state, routes, ``DataStore_*``.

:class:`LdFeed` is what :class:`~rtmu.client.session.Session` calls after login: it subscribes only
to the data the server lists and turns each packet into :class:`~rtmu.model.observables.RobotState` changes
through the session's ``update`` function. A serverDemo-like server lists none of it, so nothing
is asked and the model keeps its defaults (no laser, ``dock_state`` None, no routes).
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Coroutine
from typing import Any

from ..protocol.errors import ProtocolError
from ..protocol.payloads.ld import DataStoreValue, DockInfo, Routes
from ..protocol.payloads.map import Goals
from ..protocol.payloads.sensors import RangeDeviceReadings
from .connection import AriaClient, Packet
from .errors import ClientError
from .ld_data import LASER_NAMES, data_store_names, store_fields

LASER_INTERVAL_MS = 200
DATA_STORE_INTERVAL_MS = 1000
DOCK_INTERVAL_MS = 1000
"""``dockInfo`` is polled as well as heard on ``dockInfoChanged``: a missed broadcast heals."""

Update = Callable[..., None]
Decode = Callable[[str, bytes], Any]
Spawn = Callable[[Coroutine[Any, Any, None], str], None]


class LdFeed:
    """LD data subscriptions for one session; ``update(**changes)`` changes the published robot."""

    def __init__(self, update: Update, decode: Decode, spawn: Spawn, reply_timeout: float) -> None:
        self._update = update
        self._decode = decode
        self._spawn = spawn
        self._timeout = reply_timeout
        self._lasers: dict[str, tuple[tuple[int, int], ...]] = {}
        self._store: dict[str, str] = {}
        self._descriptions: dict[str, str] = {}

    def subscribe(self, client: AriaClient) -> None:
        """Subscribe to what the server lists (called after every login)."""
        self._lasers.clear()
        self._store.clear()
        for name in LASER_NAMES:
            if client.supports(name):
                client.request(name, LASER_INTERVAL_MS, self.on_laser)
        if client.supports("dockInfo"):
            client.request("dockInfo", DOCK_INTERVAL_MS, self._on_dock)
        if client.supports("dockInfoChanged"):
            client.request("dockInfoChanged", -1, self._on_dock)
        if client.supports("routesUpdated") and client.supports("getRoutes"):
            client.request("routesUpdated", -1, lambda packet: self._refetch_routes(client))
        self._descriptions = {e.name: e.description for e in client.datalist}
        for name in data_store_names(client):
            client.request(name, DATA_STORE_INTERVAL_MS, self._on_store)

    async def fetch(self, client: AriaClient) -> None:
        """One-off questions after login: the route list, and the goals ``gotoRouteGoal`` can reach."""
        if client.supports("getRoutes"):
            with contextlib.suppress(ClientError, ProtocolError):
                reply = await client.request_once("getRoutes", timeout=self._timeout)
                routes = self._decode("getRoutes", reply.payload)
                if isinstance(routes, Routes):
                    self._update(routes=routes.routes)
        if client.supports("gotoRouteGoal") and client.supports("getGoals"):
            with contextlib.suppress(ClientError, ProtocolError):
                reply = await client.request_once("getGoals", timeout=self._timeout)
                goals = self._decode("getGoals", reply.payload)
                if isinstance(goals, Goals):
                    self._update(goals=goals.goals)

    def _refetch_routes(self, client: AriaClient) -> None:
        self._spawn(self.fetch(client), "ld-routes")

    def goals_updated(self, client: AriaClient) -> None:
        """``goalsUpdated`` (the session holds that one subscription for navigation too): ask again."""
        if client.supports("gotoRouteGoal"):
            self._refetch_routes(client)

    def on_laser(self, packet: Packet) -> None:
        """A ``Laser_*Current`` packet (also handed on by the drawings feed when it holds that request)."""
        readings = self._decode(packet.name, packet.payload)
        if isinstance(readings, RangeDeviceReadings):
            self._lasers[packet.name] = readings.readings
            points = tuple(p for name in sorted(self._lasers) for p in self._lasers[name])
            self._update(laser=points, laser_at=packet.received_at)

    def _on_dock(self, packet: Packet) -> None:
        info = self._decode(packet.name, packet.payload)
        if isinstance(info, DockInfo):
            self._update(dock_state=info.state_label)

    def _on_store(self, packet: Packet) -> None:
        value = self._decode(packet.name, packet.payload)
        if isinstance(value, DataStoreValue) and self._store.get(packet.name) != value.value:
            self._store[packet.name] = value.value
            fields = store_fields(packet.name, value.value, self._descriptions.get(packet.name, ""))
            self._update(data_store=tuple(sorted(self._store.items())), **fields)

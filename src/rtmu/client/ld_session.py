"""The session's share of LD (ARAM) data: lasers, docking state, routes, ``DataStore_*``; patrol and say.

The lasers are every robot's: an LD robot's ``Laser_*Current`` and an ARIA/Pioneer server's laser
drawings (``sim_lms2xx_1Current`` …, :func:`~rtmu.client.ld_data.laser_names`), so the recorder and the
Foxglove bridge have the laser of both.

:class:`LdFeed` subscribes only to the data the server lists and turns each packet into
:class:`~rtmu.values.state.RobotState` changes. A serverDemo-like server lists none of it, so nothing
is asked and the model keeps its defaults (no laser, ``dock_state`` None, no routes). The goal list
is navigation's (:class:`~rtmu.client.nav_session.NavFeed`): one ``getGoals`` per update.
"""

from __future__ import annotations

import contextlib
import itertools
from collections.abc import Iterable
from typing import ClassVar

from ..protocol.errors import ProtocolError
from ..protocol.payloads.ld import DataStoreValue, DockInfo, Routes
from ..protocol.payloads.ld import Patrol as PatrolPayload
from ..protocol.payloads.ld import Say as SayPayload
from ..protocol.payloads.sensors import RangeDeviceReadings
from ..values.intents import Intent, Patrol, Say
from .call_values import Packet
from .connection import AriaClient
from .errors import ClientError
from .feed import Feed, FeedContext
from .ld_data import NAV_FIELDS, data_store_names, laser_names, store_fields
from .nav_session import NavFeed
from .subscriptions import Subscription

LASER_INTERVAL_MS = 200
DATA_STORE_INTERVAL_MS = 1000
DOCK_INTERVAL_MS = 1000
"""``dockInfo`` is polled as well as heard on ``dockInfoChanged``: a missed broadcast heals."""


class LdFeed(Feed):
    """LD data subscriptions for one session, and the LD robot's own intents (patrol a route, speak)."""

    handles: ClassVar[tuple[type[Intent], ...]] = (Patrol, Say)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self._lasers: dict[str, tuple[tuple[int, int], ...]] = {}
        self._store: dict[str, str] = {}
        self._descriptions: dict[str, str] = {}

    def subscriptions(self, client: AriaClient) -> Iterable[Subscription]:
        subs = [Subscription(name, LASER_INTERVAL_MS, self.on_laser) for name in laser_names(client)]
        subs += [
            Subscription("dockInfo", DOCK_INTERVAL_MS, self._on_dock),
            Subscription("dockInfoChanged", -1, self._on_dock),
            Subscription("routesUpdated", -1, self._on_routes_changed, needs="getRoutes"),
            Subscription("goalsUpdated", -1, self._on_routes_changed, needs="gotoRouteGoal"),
        ]
        subs += [
            Subscription(name, DATA_STORE_INTERVAL_MS, self._on_store) for name in data_store_names(client)
        ]
        return subs

    def connected(self, client: AriaClient) -> None:
        self._lasers.clear()
        self._store.clear()
        self._descriptions = {e.name: e.description for e in client.datalist}
        self.ctx.spawn(self._fetch_routes(client), "ld-routes")

    def handle(self, intent: Intent) -> None:
        if isinstance(intent, Patrol):
            self.require("patrol").send(PatrolPayload(intent.route))
        elif isinstance(intent, Say):
            self.require("say").send(SayPayload(intent.text))

    async def _fetch_routes(self, client: AriaClient) -> None:
        if client.supports("getRoutes"):
            with contextlib.suppress(ClientError, ProtocolError):
                reply = await client.request_once("getRoutes", timeout=self.ctx.config.reply_timeout)
                routes = self.ctx.decode("getRoutes", reply.payload)
                if isinstance(routes, Routes):
                    self.ctx.robot_update(routes=routes.routes)

    def _on_routes_changed(self, packet: Packet) -> None:
        client = self.ctx.client
        if client is not None:
            self.ctx.spawn(self._fetch_routes(client), "ld-routes")

    def on_laser(self, packet: Packet) -> None:
        """A laser's ``…Current`` packet (also handed on by the drawings feed when it holds that request)."""
        readings = self.ctx.decode(packet.name, packet.payload)
        if isinstance(readings, RangeDeviceReadings):
            lasers = self._lasers
            lasers[packet.name] = readings.readings
            if len(lasers) == 1:  # one laser (most robots): its readings as they are, not rebuilt
                points = tuple(readings.readings)  # the same tuple: no copy
            else:
                points = tuple(itertools.chain.from_iterable(lasers[name] for name in sorted(lasers)))
            self.ctx.robot_update(laser=points, laser_at=packet.received_at)

    def _on_dock(self, packet: Packet) -> None:
        info = self.ctx.decode(packet.name, packet.payload)
        if isinstance(info, DockInfo):
            self.ctx.robot_update(dock_state=info.state_label)

    def _on_store(self, packet: Packet) -> None:
        value = self.ctx.decode(packet.name, packet.payload)
        if isinstance(value, DataStoreValue) and self._store.get(packet.name) != value.value:
            self._store[packet.name] = value.value
            fields = store_fields(packet.name, value.value, self._descriptions.get(packet.name, ""))
            nav = {k: v for k, v in fields.items() if k in NAV_FIELDS}
            robot = {k: v for k, v in fields.items() if k not in NAV_FIELDS}
            self.ctx.robot_update(data_store=tuple(sorted(self._store.items())), **robot)
            if nav:
                self.ctx.feed(NavFeed).robot_reports(**nav)

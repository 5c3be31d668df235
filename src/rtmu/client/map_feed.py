"""The map of the connected server: downloaded once per map file, reloaded when the server says so.

Requests merge: while a download is in flight, asking again (:class:`LoadMap`, or any number of
``mapUpdated`` broadcasts) only marks the map dirty, and ONE more download starts when the current
one ends — a storm of broadcasts costs two downloads, not hundreds. A reconnect to the same map
(same ``getMapId``) costs none (:class:`~rtmu.client.mapcache.MapCache`), and a fleet's sessions
download each map file once between them (``SessionConfig.shared_maps``).
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Iterable
from dataclasses import replace
from typing import ClassVar

from ..base.i18n import _
from ..base.notices import Kind, Notice
from ..values.intents import Intent, LoadMap
from ..values.state import MapChanged, MapModel, MapPhase
from .call_values import Packet
from .connection import AriaClient
from .errors import ClientError, ProtocolFault, ServerClosed
from .feed import Feed, FeedContext
from .mapcache import MapCache, MapKey, content_key, map_key
from .mapload import download_map, map_source
from .subscriptions import Subscription

log = logging.getLogger(__name__)


class MapFeed(Feed):
    """The session's map (network loop only); ``value`` is the map as last published."""

    handles: ClassVar[tuple[type[Intent], ...]] = (LoadMap,)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self.value = MapModel()
        self._cache = MapCache()
        self._task: asyncio.Task[MapModel] | None = None
        self._dirty = False
        """The map changed (or was asked for) while a download was in flight: fetch once more."""
        self.downloads_skipped = 0
        """Map loads answered from the cache (same ``getMapId``): what a reconnect saved."""
        self.downloads_shared = 0
        """Map loads answered by another session's download of the same map (``config.shared_maps``)."""

    @property
    def downloading(self) -> bool:
        task = self._task
        return task is not None and not task.done()

    def subscriptions(self, client: AriaClient) -> Iterable[Subscription]:
        return (Subscription("mapUpdated", -1, self._on_map_updated),)

    def connected(self, client: AriaClient) -> None:
        if self.ctx.config.fetch_map:
            self.request()

    def disconnected(self) -> None:
        self._set(MapModel())

    def handle(self, intent: Intent) -> asyncio.Future[MapModel]:
        """Download the map (``getMapBinary`` when offered, else ``getMap``), publish it, return it."""
        self.require()
        return asyncio.shield(self.request())

    def _on_map_updated(self, packet: Packet) -> None:
        if self.ctx.config.fetch_map:
            self.request()

    def _set(self, value: MapModel) -> None:
        self.value = value
        self.ctx.publish(MapChanged(value))

    def request(self) -> asyncio.Task[MapModel]:
        """Start a download, or mark the one in flight dirty (then one more follows it)."""
        task = self._task
        if task is not None and not task.done():
            self._dirty = True
            return task
        self._dirty = False
        task = self._task = asyncio.get_running_loop().create_task(self._loader(), name="session-map")
        self.ctx.spawn(_wait(task), "map")  # the connection's tasks end it with the connection
        return task

    async def _loader(self) -> MapModel:
        while True:
            self._dirty = False
            result = await self._load_once()
            client = self.ctx.client
            if not self._dirty or client is None or not client.connected:
                return result

    async def _load_once(self) -> MapModel:
        client = self.require()
        if map_source(client) is None:
            self._set(MapModel(state=MapPhase.UNSUPPORTED))
            return self.value
        target = self.ctx.target
        key = None
        if target is not None:
            key = await map_key(client, target.host, target.port, self.ctx.config.reply_timeout)
        cached = self._cache.get(key)
        if cached is not None:  # the same map as last time (reconnect, spurious mapUpdated)
            self.downloads_skipped += 1
            if cached != self.value or cached.data is not self.value.data:
                self._set(cached)
            return self.value
        shared, content = self.ctx.config.shared_maps, content_key(key)
        if shared is None or content is None:
            return await self._download(client, key)
        found, pending = shared.claim(content)
        if pending is not None:
            found = await shared.wait(pending)
        if found is None:
            if pending is not None:  # the other download failed: this session fetches its own
                return await self._download(client, key)
            model = None
            try:
                model = await self._download(client, key)
            finally:
                shared.finish(content, model if model is not None and model.state == MapPhase.READY else None)
            return model
        if not client.connected:
            raise ServerClosed("not connected")
        self.downloads_shared += 1
        self._set(replace(found, generation=self.value.generation + 1))
        self._cache.put(key, self.value)
        return self.value

    async def _download(self, client: AriaClient, key: MapKey | None) -> MapModel:
        generation = self.value.generation
        self._set(MapModel(state=MapPhase.LOADING, name=self.value.name, generation=generation))

        def progress(count: int) -> None:
            self._set(replace(self.value, received=count))

        try:
            got = await download_map(client, timeout=self.ctx.config.reply_timeout, progress=progress)
        except ProtocolFault as exc:  # the map itself is at fault: keep the verdict for this map
            failed = self._failed(client, str(exc))
            self._cache.put(key, failed)
            return failed
        except ClientError as exc:
            return self._failed(client, str(exc))
        except Exception as exc:  # a bug must still end "loading": the window would wait for ever
            log.exception("loading the map failed")
            return self._failed(client, f"internal error: {exc}")
        if got.data is None:
            self._set(
                MapModel(state=MapPhase.NONE, name=got.name, generation=generation, received=got.packets)
            )
            return self.value
        self._set(
            MapModel(
                state=MapPhase.READY,
                data=got.data,
                name=got.name,
                generation=generation + 1,
                received=got.packets,
            )
        )
        self._cache.put(key, self.value)
        return self.value

    def _failed(self, client: AriaClient, reason: str) -> MapModel:
        self._set(replace(self.value, state=MapPhase.FAILED, error=reason))
        if client.connected:
            self.ctx.notice(
                Notice.warning(Kind.MAP, _("The map could not be loaded: {value}").format(value=reason))
            )
        return self.value


def goal_pose(model: MapModel, name: str) -> tuple[float, float, float | None] | None:
    """The map's goal called ``name``: (x, y, heading — only for a ``GoalWithHeading``); None without one."""
    data = model.data
    if data is None or not name:
        return None
    for o in data.objects:
        if o.is_goal and o.name == name:
            return (o.x, o.y, o.th if o.type.lower() == "goalwithheading" else None)
    return None


async def _wait(task: asyncio.Task[MapModel]) -> None:
    """Tie a shared download to the connection: when the connection's tasks end, so does it."""
    try:
        await asyncio.shield(task)
    except asyncio.CancelledError:
        task.cancel()
        raise
    except Exception:
        pass

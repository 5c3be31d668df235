"""Configuration care for the window: factory values, reset to default, and switching the robot's map.

The rules are :mod:`.config_care`'s (the ones ``rtmu config`` follows): factory values only where the
server keeps them (``getConfigDefaults``), a reset sent through ``setConfigParam`` for one parameter
where offered, else one ``setConfig``, the server's own words as the answer. Switching the map sets
ARNL's ``Files/Map`` parameter — the server loads the file when the value is taken — and then asks
``checkMap`` where offered; the answer says whether ``mapUpdated`` followed (the map feed reloads on it).
This feed hears ``mapUpdated`` through the session's subscriptions (shared with the map feed): a
session's connection must not be asked for it a second time.
"""

from __future__ import annotations

import asyncio
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any, ClassVar

from ..values.intents import FetchConfigDefaults, Intent, ResetConfig, SwitchMap
from .call_values import Packet
from .config_feed import fetch_config, set_config
from .connection import AriaClient
from .errors import NotSupported
from .feed import Feed, FeedContext
from .subscriptions import Subscription

if TYPE_CHECKING:
    from ..protocol.payloads.config import SetConfigReply


class ConfigCareFeed(Feed):
    """Carries out :class:`FetchConfigDefaults`, :class:`ResetConfig` and :class:`SwitchMap`."""

    handles: ClassVar[tuple[type[Intent], ...]] = (FetchConfigDefaults, ResetConfig, SwitchMap)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self.map_updates = 0
        self._updated: asyncio.Event | None = None

    def subscriptions(self, client: AriaClient) -> Iterable[Subscription]:
        return (Subscription("mapUpdated", -1, self._map_updated),)

    def _map_updated(self, _packet: Packet) -> None:
        self.map_updates += 1
        if self._updated is not None:
            self._updated.set()

    def handle(self, intent: Intent) -> Any:
        from .config_care import fetch_defaults, reset  # with the first intent, not at launch (issue 28)

        client = self.require()
        timeout = self.ctx.config.reply_timeout
        if isinstance(intent, FetchConfigDefaults):
            return fetch_defaults(client, timeout)
        if isinstance(intent, ResetConfig):
            return reset(client, {s: dict(v) for s, v in intent.changes.items()}, timeout)
        assert isinstance(intent, SwitchMap)
        return self._switch(client, intent.path, timeout)

    async def _switch(self, client: AriaClient, path: str, timeout: float) -> bool:
        """Set ``Files/Map`` to ``path`` (a file the robot lists); True once ``mapUpdated`` came."""
        from ..protocol.payloads.configcare import CheckMap
        from .config_care import MAP_PARAM, MAP_SECTION, map_param_problem
        from .remote_files import Refused, remote_path  # with the first switch, not at launch

        path = remote_path(path)
        config = await fetch_config(client, timeout)
        problem = map_param_problem(config)
        if problem:
            raise NotSupported(f"{MAP_SECTION}/{MAP_PARAM}", problem)
        before = self.map_updates
        self._updated = asyncio.Event()
        answer: SetConfigReply = await set_config(client, {MAP_SECTION: {MAP_PARAM: path}}, timeout)
        if not answer.accepted:
            raise Refused(f"the robot did not take {path!r} as its map: {answer.error}")
        if client.supports(CheckMap.DATA_NAME):
            client.send(CheckMap())
        try:
            async with asyncio.timeout(timeout):
                while self.map_updates == before:
                    self._updated.clear()
                    await self._updated.wait()
        except TimeoutError:
            return False
        return True

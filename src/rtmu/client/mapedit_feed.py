"""Live map changes from the window: one draft, applied as ONE ``processMapChanges`` series.

The sending and its verdict are :func:`~rtmu.client.map_changes.send_changes` (what ``rtmu mapedit``
uses): the series is guarded by the map's ``getMapId``, so a server whose map changed since it was read
refuses it; the verdict is said in words with what RTMU can tell about a refusal. This feed hears the
broadcasts that verdict needs for the whole connection (``mapUpdated``, ``goalsUpdated``,
``mapChangesInProgress``, ``idleProcessingPending``: shared with the map and goal feeds, which reload
on them). A draft made on a map the session has since replaced is refused here, before anything is
sent: the window rebases the draft on the new map first.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import ClassVar

from ..mapedit import ObjectChanges
from ..values.intents import ApplyMapChanges, Intent
from .call_values import Packet
from .connection import AriaClient
from .feed import Feed, FeedContext
from .map_changes import WATCHED, ChangeVerdict, ChangeWatch, map_id, object_change_set, send_changes
from .subscriptions import Subscription


class MapEditFeed(Feed):
    """Carries out :class:`ApplyMapChanges`; its answer is the server's :class:`ChangeVerdict`."""

    handles: ClassVar[tuple[type[Intent], ...]] = (ApplyMapChanges,)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self.watch = ChangeWatch()

    def subscriptions(self, client: AriaClient) -> Iterable[Subscription]:
        return tuple(Subscription(name, -1, self._heard) for name in WATCHED)

    def disconnected(self) -> None:
        self.watch = ChangeWatch()

    def _heard(self, packet: Packet) -> None:
        self.watch.hear(packet.name, packet.payload)

    async def handle(self, intent: Intent) -> ChangeVerdict:
        assert isinstance(intent, ApplyMapChanges)
        client = self.require("processMapChanges")
        timeout = self.ctx.config.reply_timeout
        shown = self.ctx.map
        if intent.generation != shown.generation or shown.data is None:
            return ChangeVerdict(
                False,
                None,
                "nothing was sent: the map changed since the draft was made; the draft now shows the new map",
            )
        changes = ObjectChanges(tuple(intent.removed), tuple(intent.added))
        guard = await map_id(client, timeout)
        return await send_changes(
            client, object_change_set(changes, shown.data), self.watch, guard=guard, timeout=timeout
        )

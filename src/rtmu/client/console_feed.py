"""The session's share of the console: the window's console page reaches any data the server lists.

:class:`ConsoleFeed` carries out the console's intents over the session's own connection, so the
flight recorder's tee records the requests and replies like any other traffic: the server's whole
data list with what RTMU reads from it (:class:`~rtmu.values.intents.ConsoleList`), one call with
typed arguments (:class:`~rtmu.values.intents.ConsoleCall`), and one data followed at an interval
(:class:`~rtmu.values.intents.ConsoleFollow`) whose replies the page collects in batches
(:class:`~rtmu.values.intents.ConsoleNext`, a long poll: the page asks again when a batch is shown,
so a fast stream never queues more than :data:`~rtmu.client.console.MAX_QUEUED` packets).

The rules are the console model's (:mod:`rtmu.client.console`), applied here on the network side
whatever the window said: a call that changes something needs ``confirmed``, ``ratioDrive`` is never
sent, a changing data is never followed, a data the session itself follows is not taken over. A
confirmed motion request ends a held drive first, as every intent that moves the robot does. Replies
are bounded (the model keeps 16 packets and 200 fields a packet; reading stops at
:data:`MAX_READ_BYTES`), so a hostile reply costs the window a bounded page.
"""

from __future__ import annotations

import asyncio
from typing import Any, ClassVar

from ..values.intents import ConsoleCall, ConsoleFollow, ConsoleList, ConsoleNext, Intent
from .connection import AriaClient
from .console import ConsoleEntry, ConsoleReply, Subscription, call, console_entries, entry_of
from .console_effect import moves_robot
from .console_layout import encode_arguments
from .drive_loop import DriveFeed
from .errors import NotSupported
from .feed import Feed, FeedContext

MAX_READ_BYTES = 4 << 20
"""Bytes of one reply read before the console stops (outcome ``cut``): the page shows 16 packets."""
MAX_READ_PACKETS = 20_000
MAX_BATCH = 8
"""Replies handed to the page per :class:`~rtmu.values.intents.ConsoleNext`."""
MAX_WAIT = 5.0
"""The longest a :class:`~rtmu.values.intents.ConsoleNext` waits for its first reply."""


class ConsoleFeed(Feed):
    """See the module notes. At most one data is followed at a time (the page follows one)."""

    handles: ClassVar[tuple[type[Intent], ...]] = (ConsoleList, ConsoleCall, ConsoleFollow, ConsoleNext)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self.following: Subscription | None = None

    def lost(self) -> None:
        self.following = None  # the connection took the subscription with it

    def disconnected(self) -> None:
        self.following = None

    def handle(self, intent: Intent) -> Any:
        if isinstance(intent, ConsoleNext):
            return self.next_replies(intent)
        client = self.require()
        if isinstance(intent, ConsoleList):
            return self.entries(client, intent.text)
        if isinstance(intent, ConsoleFollow):
            return self.follow(client, intent)
        assert isinstance(intent, ConsoleCall)
        entry = self.entry(client, intent.name)
        payload = encode_arguments(entry.arguments, list(intent.arguments), list(intent.types) or None)
        if moves_robot(entry.name) and intent.confirmed:
            self.ctx.feed(DriveFeed).end_drive("a console call takes over")
        return call(
            client,
            entry,
            payload,
            confirmed=intent.confirmed,
            timeout=self.ctx.config.reply_timeout,
            max_packets=MAX_READ_PACKETS,
            max_bytes=MAX_READ_BYTES,
        )

    @staticmethod
    def entry(client: AriaClient, name: str) -> ConsoleEntry:
        data = client.datalist.entry(name)
        if data is None:
            raise NotSupported(name, f"this server lists no data {name!r} for this user")
        return entry_of(data)

    @staticmethod
    async def entries(client: AriaClient, text: str) -> list[ConsoleEntry]:
        """The data list read (each entry's layouts and effect): off the loop, a thousand regex scans."""
        loop = asyncio.get_running_loop()
        return await loop.run_in_executor(None, console_entries, client.datalist, text)

    def follow(self, client: AriaClient, intent: ConsoleFollow) -> str | None:
        """Start following ``intent.name`` (ending the one followed before), or stop; the name followed."""
        self.stop_following()
        if not intent.on:
            return None
        entry = self.entry(client, intent.name)
        payload = encode_arguments(entry.arguments, list(intent.arguments), list(intent.types) or None)
        self.following = Subscription(client, entry, intent.interval_ms, payload).start()
        return entry.name

    def stop_following(self) -> None:
        following, self.following = self.following, None
        if following is not None:
            following.stop()

    async def next_replies(self, intent: ConsoleNext) -> tuple[ConsoleReply, ...]:
        """Up to :data:`MAX_BATCH` replies of the followed data; () when none came in time or it is not
        (or no longer) the one followed."""
        following = self.following
        if following is None or following.entry.name != intent.name:
            return ()
        first = await following.next(max(0.0, min(MAX_WAIT, intent.wait)))
        if first is None:
            return ()
        batch = [first]
        while len(batch) < MAX_BATCH and self.following is following:
            more = await following.next(0.0)
            if more is None:
                break
            batch.append(more)
        return tuple(batch)

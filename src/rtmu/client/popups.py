"""Server popups for one session (protocol §4.9): what is open, answers, and the closing words.

:class:`PopupFeed` is fed the session's ``popupCreate`` / ``popupClose`` packets (its
subscriptions) and asks ``popupList`` once per login, so a reconnect shows again what the
server still has open. It publishes the open set as one typed :class:`~rtmu.values.state.PopupsChanged`
and the server's closing text as a ``Kind.SERVER`` notice. Server text is untrusted: titles,
messages and labels are cut to a bounded length, and at most :data:`MAX_OPEN` popups are kept —
a flood beyond that is only counted. Publishing is coalesced to at most one state per
:data:`PUBLISH_EVERY` (the first change after a quiet spell goes at once), so a storm of 200 popups
a second costs the UI thread ten card rebuilds a second, not two hundred.
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import Iterable
from typing import ClassVar

from ..base.notices import Kind, Notice
from ..protocol.payloads.popup import PopupClicked, PopupClose, PopupCreate
from ..values.intents import AnswerPopup, Intent
from ..values.state import PopupInfo, PopupsChanged, PopupsState
from .call_values import Packet
from .connection import AriaClient
from .errors import ClientError
from .feed import Feed, FeedContext
from .subscriptions import Subscription

MAX_OPEN = 64
"""Open popups kept; more are counted in ``PopupsState.dropped`` (a window shows only a few anyway)."""
MAX_TITLE = 200
MAX_MESSAGE = 2000
MAX_LABEL = 40
MAX_CLOSE_TEXT = 300
PUBLISH_EVERY = 0.1
"""Seconds between two published popup states at least."""


def cut(text: str, limit: int) -> str:
    """At most ``limit`` characters; a cut text ends in "…" so the operator sees it was cut."""
    return text if len(text) <= limit else text[: limit - 1] + "…"


def popup_info(p: PopupCreate, at: float) -> PopupInfo:
    labels = tuple(cut(b, MAX_LABEL) for b in p.buttons[:3])
    return PopupInfo(
        p.popup_id,
        cut(p.title, MAX_TITLE),
        cut(p.message, MAX_MESSAGE),
        p.popup_type if 0 <= p.popup_type <= 4 else 0,
        labels + ("",) * (3 - len(labels)),
        p.default_button,
        p.escape_button,
        at,
    )


class PopupFeed(Feed):
    """The open popups of one session (network loop only)."""

    handles: ClassVar[tuple[type[Intent], ...]] = (AnswerPopup,)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self._open: dict[int, PopupInfo] = {}
        self._dropped = 0
        self._offered = False
        self._client: AriaClient | None = None
        self._dirty = False
        self._published_at = float("-inf")
        self.state = PopupsState()

    def subscriptions(self, client: AriaClient) -> Iterable[Subscription]:
        return (
            Subscription("popupCreate", -1, self.on_create),
            Subscription("popupClose", -1, self.on_close),
        )

    # -- connection --------------------------------------------------------------------------
    def connected(self, client: AriaClient) -> None:
        """A fresh login: forget the last link's popups and ask this server which are open."""
        self._client = client
        self._open.clear()
        self._dropped = 0
        self._offered = client.supports("popupCreate")
        self._flush()
        if self._offered and client.supports("popupList"):
            self.ctx.spawn(self._list(client), "popup-list")

    def disconnected(self) -> None:
        self._client = None
        self._open.clear()
        self._dropped = 0
        self._offered = False
        self._flush()

    async def _list(self, client: AriaClient) -> None:
        # The open ones come as popupCreate packets (the subscription hears them), then an empty
        # popupList packet ends the reply.
        with contextlib.suppress(ClientError):
            await client.request_once("popupList", timeout=self.ctx.config.reply_timeout)

    # -- packets -----------------------------------------------------------------------------
    def on_create(self, packet: Packet) -> None:
        p = self.ctx.decode(packet.name, packet.payload)
        if not isinstance(p, PopupCreate):
            return
        if p.popup_id not in self._open and len(self._open) >= MAX_OPEN:
            self._dropped += 1
        else:
            self._open[p.popup_id] = popup_info(p, self.ctx.clock())
        self._changed()

    def on_close(self, packet: Packet) -> None:
        c = self.ctx.decode(packet.name, packet.payload)
        if not isinstance(c, PopupClose):
            return
        gone = self._open.pop(c.popup_id, None)
        if gone is None:  # not one we keep: most likely one a flood made us drop, now closed
            if self._dropped > 0:
                self._dropped -= 1
                self._changed()
            return
        self._changed()
        text = cut(c.message.strip(), MAX_CLOSE_TEXT)
        if text:
            self.ctx.notice(Notice.info(Kind.SERVER, f"{gone.title}: {text}" if gone.title else text))

    # -- answers -----------------------------------------------------------------------------
    def handle(self, intent: Intent) -> None:
        """The operator pressed a button (0–2): tell the server; its ``popupClose`` removes the card."""
        assert isinstance(intent, AnswerPopup)
        if not 0 <= intent.button <= 2:
            raise ValueError(f"a popup has buttons 0–2, not {intent.button}")
        self.require("popupClicked").send(PopupClicked(intent.popup_id, intent.button))

    # -- publishing (coalesced) --------------------------------------------------------------
    def _changed(self) -> None:
        if self._dirty:
            return
        self._dirty = True
        try:
            loop = asyncio.get_running_loop()
        except RuntimeError:  # no loop (a test feeding packets by hand): publish now
            self._flush()
            return
        loop.call_later(max(0.0, self._published_at + PUBLISH_EVERY - self.ctx.clock()), self._flush)

    def _flush(self) -> None:
        self._dirty = False
        self._published_at = self.ctx.clock()
        state = PopupsState(tuple(self._open.values()), self._dropped, self._offered)
        if state != self.state:
            self.state = state
            self.ctx.publish(PopupsChanged(state))

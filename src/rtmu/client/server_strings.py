"""The server's information strings (``getStringsInfo`` / ``getStrings``, protocol §4.11) for one session.

ARIA servers publish extra status (CPU, Wi-Fi, odometer, uptime …) as labelled, pre-formatted
strings. One ``getStrings`` subscription serves two readers: the Wi-Fi gauges (held whenever a
label names a wireless value) and the details table (held only while it is open, so a closed
table costs the robot nothing). Everything is bounded before it reaches the model: at most
:data:`MAX_ITEMS` rows of at most :data:`MAX_TEXT` characters each; the rest is only counted.
"""

from __future__ import annotations

import contextlib
from typing import Any, ClassVar

from ..protocol.errors import ProtocolError
from ..protocol.payloads.strings import Strings, StringsInfo
from ..values.intents import Intent, WatchStrings
from .call_values import Packet
from .connection import AriaClient
from .errors import ClientError
from .feed import Feed, FeedContext

INTERVAL_MS = 1000
MAX_ITEMS = 200
"""Rows kept for the table; a hostile server may list thousands (a packet holds ~10 000)."""
MAX_TEXT = 120
"""Characters kept of a label or value (ARIA's own are under 40)."""
_WIFI_WORDS = ("wireless", "wifi", "wi-fi", "wlan")


def clip(text: str) -> str:
    """``text`` cut to :data:`MAX_TEXT` characters (an ellipsis says it was cut)."""
    return text if len(text) <= MAX_TEXT else text[: MAX_TEXT - 1] + "…"


def wifi_role(label: str) -> str | None:
    """Which RobotState field a ``getStrings`` item feeds, judged from its label."""
    low = label.lower()
    if "quality" in low and (any(w in low for w in _WIFI_WORDS) or "link" in low):
        return "wifi_quality"
    if "signal" in low or ("dbm" in low and any(w in low for w in _WIFI_WORDS)):
        return "wifi_signal"
    return None


WIFI_QUALITY_SCALE = 70
"""ARIA publishes the wireless link quality as Linux reads it (``/proc/net/wireless``: 0–70)."""


def quality_percent(raw: int | None) -> int | None:
    """A published link quality (0–70) in %: the one unit the window, the alarm and an LD robot use."""
    if raw is None:
        return None
    return round(max(0.0, min(100.0, raw * 100 / WIFI_QUALITY_SCALE)))


def _prefix_end(payload: bytes, count: int) -> int:
    """Where the first ``count`` NUL-terminated strings of ``payload`` end (all of it if fewer)."""
    end = 0
    for _ in range(count):
        found = payload.find(b"\0", end)
        if found < 0:
            return len(payload)
        end = found + 1
    return end


def _int_or_none(text: str) -> int | None:
    try:
        return round(float(text.split()[0]))
    except (ValueError, IndexError, OverflowError):
        return None


class StringsFeed(Feed):
    """Holds the ``getStrings`` subscription while someone reads it; the values feed the robot."""

    handles: ClassVar[tuple[type[Intent], ...]] = (WatchStrings,)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self._client: AriaClient | None = None
        self._info: StringsInfo | None = None
        self._labels: tuple[str, ...] = ()
        """The first :data:`MAX_ITEMS` labels, clipped: what the table can show."""
        self._roles: tuple[tuple[int, str], ...] = ()
        """(index, RobotState field) of the Wi-Fi items among those labels."""
        self._held = False
        self._refetching = False
        self.watching = False
        """The details table is open (an operator's :class:`WatchStrings`)."""
        self.interval_ms = ctx.config.wifi_interval_ms

    @property
    def _wifi(self) -> bool:
        return bool(self._roles)

    def connected(self, client: AriaClient) -> None:
        self._client, self._info, self._held, self._labels, self._roles = client, None, False, (), ()
        self.ctx.spawn(self._start(client), "strings")

    async def _start(self, client: AriaClient) -> None:
        """Read the labels once after login, then subscribe if anyone reads the values."""
        if client.supports("getStringsInfo") and client.supports("getStrings"):
            await self._fetch_info(client)
        self._sync()

    def disconnected(self) -> None:
        self._client, self._info, self._held = None, None, False
        if self.watching:
            self.ctx.robot_update(server_strings=(), server_strings_more=0)

    def handle(self, intent: Intent) -> None:
        assert isinstance(intent, WatchStrings)
        self.watch(intent.on)

    def watch(self, on: bool) -> None:
        """The details table opened (True) or closed (False): ask for the values only while open."""
        self.watching = on
        self._sync()
        if not on:
            self.ctx.robot_update(server_strings=(), server_strings_more=0)

    async def _fetch_info(self, client: AriaClient) -> None:
        with contextlib.suppress(ClientError, ProtocolError):
            reply = await client.request_once("getStringsInfo", timeout=self.ctx.config.reply_timeout)
            info = self.ctx.decode("getStringsInfo", reply.payload)
            if isinstance(info, StringsInfo) and client is self._client:
                self._set_info(info)

    def _set_info(self, info: StringsInfo) -> None:
        # Worked out once per label list, not per packet: a hostile list may hold 10 000 labels.
        self._info = info
        shown = info.items[:MAX_ITEMS]
        self._labels = tuple(clip(item.label) for item in shown)
        roles = ((i, wifi_role(item.label)) for i, item in enumerate(shown))
        self._roles = tuple((i, role) for i, role in roles if role is not None)

    def _sync(self) -> None:
        client = self._client
        if client is None or not client.connected or self._info is None:
            return
        wanted = self.watching or self._wifi
        if wanted and not self._held:
            self._held = True
            client.request("getStrings", self.interval_ms, self._on_values)
        elif not wanted and self._held:
            self._held = False
            client.stop_request("getStrings")

    def _on_values(self, packet: Packet) -> None:
        """Values in label order. Only the first :data:`MAX_ITEMS` are decoded; the rest are counted.

        This runs on the network loop: a 10 000-value packet must cost it no more than a few
        hundred (``bench/bench_ptz.py``), so the tail is counted by its terminators, not parsed.
        """
        info = self._info
        if info is None:
            return
        payload = packet.payload
        total = payload.count(b"\0")
        cut = _prefix_end(payload, MAX_ITEMS)
        try:
            values = Strings.decode(payload[:cut]).values
        except ProtocolError:
            return
        if total != len(info.items) and not self._refetching and self._client is not None:
            self._refetching = True  # an item was added since we read the labels: read them again
            self.ctx.spawn(self._refetch(self._client), "strings-info")
        changes: dict[str, Any] = {}
        for i, role in self._roles:
            if i < len(values):
                number = _int_or_none(values[i])
                changes[role] = quality_percent(number) if role == "wifi_quality" else number
        if self.watching:
            shown = min(len(values), len(self._labels))
            changes["server_strings"] = tuple(
                zip(self._labels[:shown], map(clip, values[:shown]), strict=True)
            )
            changes["server_strings_more"] = max(0, min(total, len(info.items)) - shown)
        if changes:
            self.ctx.robot_update(**changes)

    async def _refetch(self, client: AriaClient) -> None:
        try:
            await self._fetch_info(client)
            self._sync()
        finally:
            self._refetching = False

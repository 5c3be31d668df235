"""The console: any data a server lists, called once or followed at an interval — the model, no GTK.

An LD robot lists about a thousand data; RTMU has code for about a hundred. The console lets a field
engineer use the rest: :func:`console_entries` is the server's whole data list with everything it
sent about each data (description, argument and return descriptions, command group, flags) plus
what RTMU reads from it — the argument layout (:mod:`~rtmu.client.console_layout`) and whether a
call changes something (:mod:`~rtmu.client.console_effect`). :func:`call` sends one request and
collects its reply as :class:`ConsoleReply` (each packet as bytes, fields and RTMU's own type,
:mod:`~rtmu.client.console_reply`); :class:`Subscription` follows a data at an interval.

The safety rules live here, once, for the command line and the window alike: a call that changes
something needs ``confirmed=True`` (:class:`NeedsConfirmation` otherwise, saying why);
``ratioDrive`` is refused (held motion comes only from a held drive); nothing that changes
something is subscribed to (a subscription repeats its request at the interval); and a data the
session itself follows is not taken over (its subscription would be replaced, then stopped).

Everything goes through the :class:`~rtmu.client.connection.AriaClient` it is given, so the
flight recorder's tee sees the requests and replies like any other traffic. Replies are bounded:
the first :data:`MAX_PACKETS_KEPT` packets are kept and viewed, the rest counted, and reading
stops after :data:`MAX_READ_PACKETS` packets or :data:`MAX_READ_BYTES` bytes.
"""

from __future__ import annotations

import asyncio
import time
from collections import deque
from dataclasses import dataclass
from typing import Any

from ..base.exit_codes import EXIT_USAGE
from ..protocol.datalist import DataEntry, DataList
from .call_values import Packet
from .connection import AriaClient
from .console_effect import HELD_MOTION, Effect, classify
from .console_layout import Layout, describe, parse_layout
from .console_reply import PacketView, view_packet
from .custom_commands import taken
from .errors import ClientError, ClientTimeout, NotSupported

MAX_PACKETS_KEPT = 16
MAX_READ_PACKETS = 100_000
MAX_READ_BYTES = 64 << 20
MAX_QUEUED = 64
"""Subscription packets waiting to be read; older ones are dropped (and counted) past this."""


@dataclass(frozen=True, slots=True)
class ConsoleEntry:
    """One data of the server's list, with what RTMU reads from its descriptions."""

    data: DataEntry
    effect: Effect
    why: str
    """The words that decided :attr:`effect`."""
    arguments: Layout
    returns: Layout

    @property
    def name(self) -> str:
        return self.data.name

    @property
    def changes(self) -> bool:
        return self.effect is Effect.CHANGES

    @property
    def has_reply(self) -> bool:
        return "RETURN_NONE" not in self.data.flag_set

    def to_json(self) -> dict[str, Any]:
        d = self.data
        return {
            "number": d.number,
            "name": d.name,
            "description": d.description,
            "arguments": d.argument_description,
            "returns": d.return_description,
            "group": d.command_group,
            "flags": d.flags,
            "effect": self.effect.value,
            "why": self.why,
            "argument_layout": describe(self.arguments),
        }


def entry_of(data: DataEntry) -> ConsoleEntry:
    effect, why = classify(data)
    return ConsoleEntry(
        data, effect, why, parse_layout(data.argument_description), parse_layout(data.return_description)
    )


def console_entries(datalist: DataList, text: str = "") -> list[ConsoleEntry]:
    """Every data of the list (by number) whose name, description or group contains ``text``."""
    needle = text.lower()
    return [
        entry_of(d)
        for d in datalist
        if not needle
        or needle in d.name.lower()
        or needle in d.description.lower()
        or needle in d.command_group.lower()
    ]


class ConsoleRefusal(ClientError):
    """The console will not make this call (the reason says why); nothing was sent."""

    exit_code = EXIT_USAGE
    kind = "refused"


class NeedsConfirmation(ConsoleRefusal):
    """The call changes something and was not confirmed; nothing was sent."""

    def __init__(self, entry: ConsoleEntry) -> None:
        self.entry = entry
        super().__init__(
            f"{entry.name} changes something ({entry.why}); confirm to send it (rtmu call: --yes)"
        )


@dataclass(frozen=True, slots=True)
class ConsoleReply:
    """What came back for one call (or one subscription packet)."""

    name: str
    outcome: str
    """``replied``; ``taken`` (a command with no reply, and the server answered a request sent
    after it); ``sent`` (no reply, and no proof it was taken); ``silent`` (nothing within the
    timeout); ``stalled`` (some packets, then nothing); ``cut`` (reading stopped at the bounds)."""
    packets: tuple[PacketView, ...] = ()
    packet_count: int = 0
    byte_count: int = 0
    seconds: float = 0.0
    dropped: int = 0
    """Subscription packets dropped because the reader fell behind."""

    @property
    def answered(self) -> bool:
        return self.outcome in ("replied", "taken", "cut", "stalled")

    def to_json(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "outcome": self.outcome,
            "packet_count": self.packet_count,
            "bytes": self.byte_count,
            "seconds": round(self.seconds, 3),
            "packets": [p.to_json() for p in self.packets],
            **({"dropped": self.dropped} if self.dropped else {}),
        }


def check_call(client: AriaClient, entry: ConsoleEntry, *, confirmed: bool) -> None:
    """Raise when the console must not send ``entry`` (see the module notes)."""
    if not client.supports(entry.name):
        raise NotSupported(entry.name)
    if entry.name in HELD_MOTION:
        raise ConsoleRefusal(
            f"{entry.name} is never sent from the console: held motion comes only from a held drive "
            "(the window's keys, the gamepad's dead-man, rtmu drive)"
        )
    if entry.changes and not confirmed:
        raise NeedsConfirmation(entry)


async def call(
    client: AriaClient,
    entry: ConsoleEntry,
    payload: bytes = b"",
    *,
    confirmed: bool = False,
    timeout: float = 5.0,
    max_packets: int = MAX_READ_PACKETS,
    max_bytes: int = MAX_READ_BYTES,
) -> ConsoleReply:
    """Send ``entry`` once with ``payload`` (its encoded arguments) and collect its reply; reading
    stops (outcome ``cut``) after ``max_packets`` packets or ``max_bytes`` bytes."""
    check_call(client, entry, confirmed=confirmed)
    started = time.monotonic()
    if not entry.has_reply:
        client.send(entry.name, payload)
        outcome = "taken" if await taken(client, timeout) else "sent"
        return ConsoleReply(entry.name, outcome, seconds=time.monotonic() - started)
    kept: list[bytes] = []
    count = size = 0
    outcome = "replied"
    try:
        async for chunk in client.stream(entry.name, payload, timeout=timeout):
            count += 1
            size += len(chunk)
            if len(kept) < MAX_PACKETS_KEPT:
                kept.append(chunk)
            if count >= max_packets or size >= max_bytes:
                outcome = "cut"
                break
    except ClientTimeout:
        outcome = "stalled" if count else "silent"
    # Views of up to 16 × 32 KB packets are a few ms of work: not on the network loop.
    views = await asyncio.get_running_loop().run_in_executor(None, _views, entry, kept)
    return ConsoleReply(entry.name, outcome, views, count, size, time.monotonic() - started)


def _views(entry: ConsoleEntry, payloads: list[bytes]) -> tuple[PacketView, ...]:
    return tuple(view_packet(entry.name, p, entry.returns) for p in payloads)


class Subscription:
    """Follow one data at ``interval_ms`` (−1: only what the server broadcasts); read with :meth:`next`.

    Its handler runs on the network loop and only queues the packet (at most :data:`MAX_QUEUED`,
    the oldest dropped first); :meth:`next` makes the views. Stop it with :meth:`stop`.
    """

    def __init__(
        self, client: AriaClient, entry: ConsoleEntry, interval_ms: int, payload: bytes = b""
    ) -> None:
        self.client = client
        self.entry = entry
        self.interval_ms = interval_ms
        self.payload = payload
        self.received = 0
        self.dropped = 0
        self._queue: deque[Packet] = deque()
        self._arrived = asyncio.Event()
        self._started = False

    def start(self) -> Subscription:
        check_call(self.client, self.entry, confirmed=True)  # listed, and not held motion
        if self.entry.changes:
            raise ConsoleRefusal(
                f"{self.entry.name} changes something ({self.entry.why}): a subscription would repeat it "
                "at every interval, so the console only sends it once"
            )
        if self.client.subscribed(self.entry.name):
            raise ConsoleRefusal(
                f"this connection already follows {self.entry.name}; a second subscription would replace "
                "it — call it once instead"
            )
        self.client.request(self.entry.name, self.interval_ms, self._on_packet, self.payload)
        self._started = True
        return self

    def _on_packet(self, packet: Packet) -> None:
        self.received += 1
        self._queue.append(packet)
        if len(self._queue) > MAX_QUEUED:
            self._queue.popleft()
            self.dropped += 1
        self._arrived.set()

    async def next(self, timeout: float) -> ConsoleReply | None:
        """The next packet as a reply, or None when none arrives within ``timeout`` s."""
        if not self._queue:
            self._arrived.clear()
            try:
                async with asyncio.timeout(timeout):
                    await self._arrived.wait()
            except TimeoutError:
                return None
        packet = self._queue.popleft()
        dropped, self.dropped = self.dropped, 0
        views = await asyncio.get_running_loop().run_in_executor(None, _views, self.entry, [packet.payload])
        return ConsoleReply(self.entry.name, "replied", views, 1, len(packet.payload), dropped=dropped)

    def stop(self) -> None:
        if self._started and self.client.connected:
            self.client.stop_request(self.entry.name)
        self._started = False

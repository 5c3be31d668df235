"""Scanning for a map (ARIA's ``ArServerHandlerMapping``): start, follow, tag loops, stop, fetch the scan.

While a scan runs the robot logs its laser and its path into ``<name>.2d`` in its files folder; the
operator drives it round the site as usual (ARIA's mapping handler refuses nothing else, so a window
that wants navigation refused while scanning says so itself). Loop tags (``mappingLoopStart`` /
``mappingLoopEnd``, simple string commands with no reply) mark where a loop begins and ends, which
helps the map builder close it. :class:`ScanWatch` follows ``mappingStatusBroadcast``, so a window hears a
scan that another client started or stopped; :class:`ScanProgress` turns poses into the "1:42, 14.2 m
driven" a banner shows. The scan's file name comes from the robot: it is checked before anything is
built from it (:func:`~rtmu.client.remote_files.checked_name`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Final

from ..base.i18n import N_, Said, as_said
from ..base.textsafe import visible
from ..protocol.errors import ProtocolError
from ..protocol.payloads.commands import StringCommandArgs
from ..protocol.payloads.mapping import (
    MAPPING_END_WORDS,
    MAPPING_START_WORDS,
    MAX_SCAN_NAME,
    MappingEndCode,
    MappingEndReply,
    MappingLoopEnd,
    MappingLoopStart,
    MappingStart,
    MappingStartCode,
    MappingStartReply,
    MappingStatus,
    MappingStatusBroadcast,
    scan_file_name,
)
from .call_values import Packet
from .connection import REPLY_TIMEOUT, AriaClient
from .custom_commands import taken
from .errors import NotSupported

SCAN_FEATURES: Final[dict[str, tuple[tuple[str, ...], str]]] = {
    "scan": (
        ("mappingStart", "mappingEnd"),
        "this robot cannot scan for a map (it offers no mappingStart/mappingEnd)",
    ),
    "scan_status": (
        ("mappingStatusBroadcast", "mappingStatus"),
        "this robot does not say whether it is scanning (it offers no mappingStatus)",
    ),
    "scan_loops": (
        ("mappingLoopStart", "mappingLoopEnd"),
        "this robot takes no loop tags while scanning (it offers no mappingLoopStart)",
    ),
}
"""Feature → (the data it needs — all for ``scan`` and ``scan_loops``, any for ``scan_status``; why not)."""
MAX_TAG: Final = 200


def scan_unavailable(client: AriaClient) -> dict[str, str]:
    """Feature → why it cannot be used with this server, for each scan feature it lacks."""
    out: dict[str, str] = {}
    for feature, (names, reason) in SCAN_FEATURES.items():
        have = [client.supports(n) for n in names]
        if not (any(have) if feature == "scan_status" else all(have)):
            out[feature] = reason + " — or this user may not use it"
    return out


def _require(client: AriaClient, feature: str) -> None:
    reason = scan_unavailable(client).get(feature)
    if reason is not None:
        raise NotSupported(SCAN_FEATURES[feature][0][0], reason)


def scan_name(name: str) -> str:
    """``name`` if a robot can make a scan file of it, else ValueError saying why (nothing is sent)."""
    from .remote_files import name_problem  # the files' rules load when a scan is named, not at launch

    if len(name) > MAX_SCAN_NAME:
        raise ValueError(Said(N_("a scan name is at most {count} characters"), count=MAX_SCAN_NAME))
    problem = name_problem(scan_file_name(name))
    if problem:
        raise ValueError(
            Said(
                N_("{name} cannot name a scan: {problem}"), name=visible(repr(name)), problem=as_said(problem)
            )
        )
    return name


@dataclass(frozen=True, slots=True)
class ScanStatus:
    name: str
    """The running scan's name as the robot reports it (``""``: no scan)."""

    @property
    def scanning(self) -> bool:
        return bool(self.name)

    @property
    def file_name(self) -> str:
        """The ``.2d`` file the scan is written to (checked: one plain name); ``""`` when none."""
        if not self.name:
            return ""
        from .remote_files import checked_name

        return checked_name(scan_file_name(self.name), "a scan named")


async def start_scan(client: AriaClient, name: str, *, timeout: float = REPLY_TIMEOUT) -> str:
    """Start a scan named ``name``; the file it is written to. Refused (exit 6) with the robot's words."""
    from ..protocol.payloads.files import code_words
    from .remote_files import Refused, malformed

    name = scan_name(name)
    _require(client, "scan")
    reply = await client.request_once(MappingStart(name), timeout=timeout)
    try:
        code = MappingStartReply.decode(reply.payload).code
    except ProtocolError as exc:
        raise malformed("answer to mappingStart", exc) from None
    if code != MappingStartCode.STARTED:
        raise Refused(f"the robot did not start the scan: {code_words(MAPPING_START_WORDS, code)}", code)
    return scan_file_name(name)


async def scan_status(client: AriaClient, *, timeout: float = REPLY_TIMEOUT) -> ScanStatus:
    """Whether a scan runs, and which."""
    _require(client, "scan_status")
    name = "mappingStatus" if client.supports("mappingStatus") else MappingStatusBroadcast.DATA_NAME
    reply = await client.request_once(name, timeout=timeout)
    try:
        status = ScanStatus(MappingStatus.decode(reply.payload).name)
    except ProtocolError as exc:
        from .remote_files import malformed

        raise malformed(f"answer to {name}", exc) from None
    status.file_name  # noqa: B018 -- refuses a name that is no plain file name, now rather than later
    return status


async def stop_scan(client: AriaClient, *, timeout: float = REPLY_TIMEOUT) -> str:
    """End the scan; the file it was written to ("" when the robot does not say). Refused with its words."""
    from ..protocol.payloads.files import code_words
    from .remote_files import Refused, malformed

    _require(client, "scan")
    file_name = ""
    if not scan_unavailable(client).get("scan_status"):
        file_name = (await scan_status(client, timeout=timeout)).file_name
    reply = await client.request_once("mappingEnd", timeout=timeout)
    try:
        code = MappingEndReply.decode(reply.payload).code
    except ProtocolError as exc:
        raise malformed("answer to mappingEnd", exc) from None
    if code != MappingEndCode.ENDED:
        raise Refused(f"the robot did not end a scan: {code_words(MAPPING_END_WORDS, code)}", code)
    return file_name


async def tag_loop(
    client: AriaClient, *, start: bool, tag: str = "1", timeout: float = REPLY_TIMEOUT
) -> bool:
    """Mark the start (or end) of a loop; True once the robot has taken it (its commands never answer).

    ARIA ignores a tag while no scan runs, so a caller that cares asks :func:`scan_status` first.
    """
    if len(tag) > MAX_TAG or visible(tag) != tag:
        raise ValueError(f"a loop tag is at most {MAX_TAG} plain characters")
    _require(client, "scan_loops")
    payload = MappingLoopStart(tag) if start else MappingLoopEnd(tag)
    client.send(payload.DATA_NAME, StringCommandArgs(payload.tag))
    return await taken(client, timeout)


class ScanWatch:
    """``mappingStatusBroadcast`` followed on one connection: the scan running now, for a banner.

    ``start()`` subscribes (broadcasts only) after asking once; ``listener(status)`` is called on the
    network loop at each change. A name that is no plain file name is ignored (and counted).
    """

    def __init__(self, client: AriaClient, listener: Callable[[ScanStatus], None] | None = None) -> None:
        self.client = client
        self.listener = listener
        self.status = ScanStatus("")
        self.bad_names = 0

    async def start(self, timeout: float = REPLY_TIMEOUT) -> ScanStatus:
        self._set(await scan_status(self.client, timeout=timeout))
        if self.client.supports(MappingStatusBroadcast.DATA_NAME):
            self.client.request(MappingStatusBroadcast.DATA_NAME, -1, self._heard)
        return self.status

    def stop(self) -> None:
        self.client.stop_request(MappingStatusBroadcast.DATA_NAME)

    def _heard(self, packet: Packet) -> None:
        try:
            status = ScanStatus(MappingStatusBroadcast.decode(packet.payload).name)
            status.file_name  # noqa: B018 -- a name that cannot be a file is not taken
        except ProtocolError:
            self.bad_names += 1
            return
        self._set(status)

    def _set(self, status: ScanStatus) -> None:
        # The start broadcast carries the file name, a status answer the scan's name: same scan.
        if status.file_name == self.status.file_name:
            return
        self.status = status
        if self.listener is not None:
            self.listener(status)


class ScanProgress:
    """How long a scan has run and how far the robot drove: ``feed(x, y, t)`` with each pose (mm, s)."""

    def __init__(self, started_at: float) -> None:
        self.started_at = started_at
        self.now = started_at
        self.metres = 0.0
        self._last: tuple[float, float] | None = None

    def feed(self, x: float, y: float, t: float) -> None:
        if self._last is not None:
            step = math.hypot(x - self._last[0], y - self._last[1])
            if step < 5_000:  # a jump (relocalised, a new map) is not driving
                self.metres += step / 1000.0
        self._last = (x, y)
        self.now = max(self.now, t)

    def text(self) -> str:
        seconds = int(self.now - self.started_at)
        from ..base.i18n import _
        from ..base.units import quantity

        driven = _("{distance} driven").format(distance=quantity(self.metres, "m", 1))
        return f"{seconds // 60}:{seconds % 60:02d}, {driven}"

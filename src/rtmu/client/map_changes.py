"""Live map changes for a client: send one change set (``processMapChanges``), wait for the verdict and
the map's reload, and check that the server's map now holds the change.

:class:`ChangeWatch` hears ``mapUpdated``, ``goalsUpdated``, ``mapChangesInProgress`` and
``idleProcessingPending``; a command subscribes it itself (:meth:`ChangeWatch.subscribe`), a session
that already subscribes those data passes each packet to :meth:`ChangeWatch.hear`. The verdict is
ARIA's one number (10 applied, 0 refused: no reason is given), said in words together with what RTMU
can tell about why — another client was changing the map, or the map changed since it was read. The
wait for it is bounded, and extended while the server says it holds idle-only requests until the
robot has stood still (ARIA applies map changes only then).
"""

from __future__ import annotations

import asyncio
import contextlib
import math
from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

from ..mapedit import ObjectChanges, describe
from ..mapfile import MapData, MapObject, map_header_lines, object_text
from ..protocol.errors import ProtocolError
from ..protocol.payloads.map import MapId
from ..protocol.payloads.mapchange import (
    CHANGE_FAILED,
    ChangeCommand,
    ChangeData,
    FileLine,
    FileLineGroup,
    LineChange,
    LineSetChange,
    MapChangePacket,
    MapChangeReply,
    MapChangeSet,
    MapChangesInProgress,
    change_packets,
)
from ..protocol.payloads.server import IdleProcessingPending
from .call_values import Packet
from .connection import REPLY_TIMEOUT, AriaClient
from .errors import ClientError, ClientTimeout, MalformedReply, NotSupported

PROCESS = MapChangePacket.DATA_NAME
UPDATE_WAIT = 10.0
"""After an applied change, how long to wait for ``mapUpdated`` before re-reading the map anyway."""
IDLE_WAIT_MAX = 600.0
"""However long the server says it waits for the robot to stand still, the verdict is awaited no longer."""
WATCHED = ("mapUpdated", "goalsUpdated", MapChangesInProgress.DATA_NAME, IdleProcessingPending.DATA_NAME)
POSITION_TOLERANCE_MM = 1.0
HEADING_TOLERANCE_DEG = 0.01


@dataclass
class ChangeWatch:
    """Broadcasts about the map, counted (all on the network loop)."""

    map_updates: int = 0
    goal_updates: int = 0
    in_progress: bool = False
    """The last ``mapChangesInProgress``: some client's change set is open."""
    idle_pending: bool = False
    """The last ``idleProcessingPending``: the server holds idle-only requests until the robot is still."""
    _heard: asyncio.Event | None = field(default=None, repr=False)

    def subscribe(self, client: AriaClient) -> None:
        """Ask for every watched broadcast the server lists (a command's own connection)."""
        for name in WATCHED:
            if client.supports(name):
                client.request(name, -1, self.on_packet)

    def on_packet(self, packet: Packet) -> None:
        self.hear(packet.name, packet.payload)

    def hear(self, name: str, payload: bytes) -> None:
        if name == "mapUpdated":
            self.map_updates += 1
        elif name == "goalsUpdated":
            self.goal_updates += 1
        elif name in (MapChangesInProgress.DATA_NAME, IdleProcessingPending.DATA_NAME):
            try:
                flag = payload[0] != 0 if payload else False
            except IndexError:  # pragma: no cover - guarded above
                flag = False
            if name == MapChangesInProgress.DATA_NAME:
                self.in_progress = flag
            else:
                self.idle_pending = flag
        self._event().set()

    def _event(self) -> asyncio.Event:
        if self._heard is None:
            self._heard = asyncio.Event()
        return self._heard

    async def heard(self, timeout: float) -> bool:
        """Wait until something is heard (True) or ``timeout`` passes (False)."""
        event = self._event()
        event.clear()
        try:
            async with asyncio.timeout(max(timeout, 0.0)):
                await event.wait()
        except TimeoutError:
            return False
        return True


@dataclass(frozen=True, slots=True)
class ChangeVerdict:
    """What the server said about a change set, in words, and what came with it."""

    applied: bool
    status: int | None
    """The reply's number (10 applied, 0 refused); None when the server sent no verdict."""
    words: str
    map_updated: bool = False
    goals_updated: bool = False


def offers_map_changes(client: AriaClient) -> bool:
    return client.supports(PROCESS)


def object_change_set(changes: ObjectChanges, base: MapData | None = None) -> MapChangeSet:
    """``changes`` as ``processMapChanges`` object lines; line numbers as in ``base``'s file when known."""
    numbers: dict[str, int] = {}
    last = 0
    if base is not None:
        for i, line in enumerate(map_header_lines(base), start=1):
            if line.startswith("Cairn: "):
                numbers.setdefault(line, i)
                last = i
    sets: list[LineSetChange] = []
    removed = [f"Cairn: {object_text(o)}" for o in changes.removed]
    if removed:
        groups = tuple(FileLineGroup(FileLine(numbers.get(t, 0), t)) for t in removed)
        sets.append(LineSetChange(ChangeData.OBJECTS, LineChange.DELETIONS, groups))
    added = [f"Cairn: {object_text(o)}" for o in changes.added]
    if added:
        groups = tuple(FileLineGroup(FileLine(last + i, t)) for i, t in enumerate(added, start=1))
        sets.append(LineSetChange(ChangeData.OBJECTS, LineChange.ADDITIONS, groups))
    return MapChangeSet(tuple(sets))


async def map_id(client: AriaClient, timeout: float = REPLY_TIMEOUT) -> MapId | None:
    """The server's ``getMapId`` (None when it does not offer one)."""
    if not client.supports("getMapId"):
        return None
    answer = (await client.request_once("getMapId", timeout=timeout)).decode()
    if not isinstance(answer, MapId):
        raise MalformedReply("getMapId did not answer with a map id")
    return answer


async def send_changes(
    client: AriaClient,
    changes: MapChangeSet,
    watch: ChangeWatch,
    *,
    guard: MapId | None = None,
    timeout: float = REPLY_TIMEOUT,
    update_wait: float = UPDATE_WAIT,
) -> ChangeVerdict:
    """Send ``changes`` as one series and return the server's verdict (``watch`` must be hearing).

    ``guard``: the id of the map the change was made against (``getMapId`` when it was read); the
    server then refuses the change if its map is no longer that one. After an applied change this
    waits up to ``update_wait`` s for ``mapUpdated``. Raises NotSupported, ClientTimeout (no verdict:
    the map may or may not have changed) and the connection's errors.
    """
    if not offers_map_changes(client):
        raise NotSupported(
            PROCESS, "this server takes no live map changes (processMapChanges, ARIA's ArMapChanger)"
        )
    packets = change_packets(changes, guard)
    busy_before = watch.in_progress
    updates_before = (watch.map_updates, watch.goal_updates)
    for packet in packets[:-1]:
        client.send(packet)
    reply = await _verdict(client, packets[-1], watch, timeout)
    if not isinstance(reply, MapChangeReply):
        raise MalformedReply(f"{PROCESS} did not answer with a ubyte2 status")
    if not reply.accepted:
        words, stale = await _refusal_words(client, reply.status, busy_before, guard, timeout)
        if stale:  # ARIA keeps a series refused as stale open: close it, or our next one would join it
            await _cancel(client, timeout)
        return ChangeVerdict(False, reply.status, words)
    if client.supports("mapUpdated"):
        deadline = asyncio.get_running_loop().time() + update_wait
        while watch.map_updates == updates_before[0]:
            left = deadline - asyncio.get_running_loop().time()
            if left <= 0 or not await watch.heard(left):
                break
    return ChangeVerdict(
        True,
        reply.status,
        "the server applied the change",
        map_updated=watch.map_updates > updates_before[0],
        goals_updated=watch.goal_updates > updates_before[1],
    )


async def _verdict(client: AriaClient, finish: MapChangePacket, watch: ChangeWatch, timeout: float) -> object:
    """The reply to the finish: ``timeout`` s, counted only while the server is not waiting for idle."""
    task = asyncio.ensure_future(client.request_once(finish, timeout=IDLE_WAIT_MAX))
    loop = asyncio.get_running_loop()
    started = quiet_since = loop.time()
    try:
        while not task.done():
            await asyncio.wait([task], timeout=0.1)
            now = loop.time()
            if watch.idle_pending:
                quiet_since = now
            elif now - quiet_since > timeout or now - started > IDLE_WAIT_MAX:
                raise ClientTimeout(
                    f"no verdict on the map change from {client.host}:{client.port} within {timeout:g} s "
                    "(the server's map may or may not have changed: read it again)"
                )
        return task.result().decode()
    finally:
        if not task.done():
            task.cancel()
            with contextlib.suppress(asyncio.CancelledError, ClientError, ProtocolError):
                await task


async def _refusal_words(
    client: AriaClient, status: int, busy: bool, guard: MapId | None, timeout: float
) -> tuple[str, bool]:
    """The refusal in words, and whether it came because the map changed under the change (stale)."""
    what = (
        "processMapChanges answered 0 (refused)"
        if status == CHANGE_FAILED
        else f"processMapChanges answered {status}, which is neither 10 (applied) nor 0 (refused)"
    )
    if busy:
        return f"the server refused the change: another client was changing the map ({what})", False
    if guard is not None:
        with contextlib.suppress(ClientError, ProtocolError):
            now = await map_id(client, timeout)
            if now is not None and _ident(now) != _ident(guard):
                return (
                    f"the server refused the change: its map changed since it was read ({what}); "
                    "read it again and redo the change",
                    True,
                )
    words = (
        f"the server refused the change ({what}; ARIA gives no reason: an object to delete that it "
        "could not find, or a change it could not apply)"
    )
    return words, False


def _ident(m: MapId) -> tuple[object, ...]:
    return (m.file_name.lower(), m.size, m.checksum)


async def _cancel(client: AriaClient, timeout: float) -> None:
    """Close any half-open change set of ours on the server (after a refused series), quietly."""
    with contextlib.suppress(ClientError, ProtocolError):
        await client.request_once(MapChangePacket(ChangeCommand.CANCEL), timeout=min(timeout, 2.0))


# -- checking the result -----------------------------------------------------------------------------


def _similar(a: MapObject, b: MapObject) -> bool:
    if a.type.lower() != b.type.lower() or a.name.lower() != b.name.lower():
        return False
    if math.hypot(a.x - b.x, a.y - b.y) > POSITION_TOLERANCE_MM:
        return False
    if abs((a.th - b.th + 180.0) % 360.0 - 180.0) > HEADING_TOLERANCE_DEG:
        return False
    ends = [(a.from_xy, b.from_xy), (a.to_xy, b.to_xy)]
    for p, q in ends:
        if (p is None) != (q is None):
            return False
        if p is not None and q is not None and math.hypot(p[0] - q[0], p[1] - q[1]) > POSITION_TOLERANCE_MM:
            return False
    return True


def not_holding(objects: Iterable[MapObject], changes: ObjectChanges) -> list[str]:
    """What a map read back lacks of ``changes``: objects not added, objects not deleted (in words)."""
    by_key: dict[tuple[str, str], list[MapObject]] = defaultdict(list)
    for obj in objects:
        by_key[(obj.type.lower(), obj.name.lower())].append(obj)

    def present(obj: MapObject, among: Sequence[MapObject] | None = None) -> bool:
        pool = among if among is not None else by_key.get((obj.type.lower(), obj.name.lower()), [])
        return any(_similar(obj, other) for other in pool)

    out = [f"{describe(o)} was not added" for o in changes.added if not present(o)]
    out += [
        f"{describe(o)} is still there"
        for o in changes.removed
        if present(o) and not present(o, changes.added)
    ]
    return out


__all__ = [
    "ChangeVerdict",
    "ChangeWatch",
    "map_id",
    "not_holding",
    "object_change_set",
    "offers_map_changes",
    "send_changes",
]

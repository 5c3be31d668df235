"""Live map changes (ARIA's ``ArMapChanger``): ``processMapChanges``, its verdict, ``mapChangesInProgress``.

A change set travels as a series of ``processMapChanges`` request packets from one client, each
starting with a ``ubyte2`` command — 0 start, 1 continue, 2 finish, 3 cancel — and two map ids
(``ArMapId::toPacket``: the map the change was made against, and the map it makes). A continue
packet then says what it carries: ``ubyte`` data type (1 summary lines, 2 info lines, 3 supplement
lines, 4 map objects, 5 points, 6 line segments), ``ubyte`` change type (0 deletions, 1 additions)
and a ``string`` scan type ("" for the default scan).

* Line sets (summary, info, supplement, objects): ``byte4`` info index (which info section, as a
  position in the server's own list ``MapInfo:``, ``MetaInfo:``, …; -1 for the others), ``byte4``
  group count (-1 in a packet that continues the previous one), then groups: ``byte4`` child count,
  ``byte4`` line number, ``string`` the file line (``Cairn: Goal …`` for an object), and per child
  ``byte4`` line number, ``string`` line.
* Points: ``byte4`` count (-1 when continuing), then that many ``byte4 x, byte4 y`` — at most 1000 a
  packet. Segments: the same with ``x1 y1 x2 y2``, at most 500 a packet.

The server keeps one change set at a time: a start from a second client while the first is busy
(active in the last 15 s) is ignored, and that client's finish is refused. Only a finish or a cancel
is answered: ``ubyte2`` 10 = applied, 0 = refused (ARIA says no more than that). On every packet whose
first id is not null the server checks it still holds that map (same file name, size and checksum,
and the second id names the same file); a finish that fails the check is refused and followed by the
server's own ``getMapId``. The ids of the *start* packet describe the result: a checksum there must
match the changed map, and a non-null id must equal the file the server writes — so a client that
cannot predict ARIA's file bytes sends null ids on start and guards with its ids on the other packets.
While a set is open the server broadcasts ``mapChangesInProgress`` 1, and 0 after the verdict; an
applied change is followed by ``mapUpdated`` and ``goalsUpdated`` to every client.

Decoding is bounded by the bytes of each packet (counts are checked before anything is allocated);
:class:`MapChangeAssembler` joins a series and bounds the whole set.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from enum import IntEnum
from typing import Final, Self

import numpy as np

from ..errors import PayloadError
from ..fields import FieldReader, FieldWriter
from ..packet import MAX_PAYLOAD
from .base import Payload, Side, SingleFlag, checked_count, register
from .map import COORD_DTYPE, MapId, coords_bytes


class ChangeCommand(IntEnum):
    """``ArMapChanger::MapChangeCommand``: where a packet stands in its series."""

    START = 0
    CONTINUE = 1
    FINISH = 2
    CANCEL = 3


class ChangeData(IntEnum):
    """``ArMapChanger::MapChangeDataType``: what a continue packet carries."""

    NONE = 0
    SUMMARY = 1
    INFO = 2
    SUPPLEMENT = 3
    OBJECTS = 4
    POINTS = 5
    LINES = 6


class LineChange(IntEnum):
    """``ArMapChangeDetails::MapLineChangeType``."""

    DELETIONS = 0
    ADDITIONS = 1


LINE_SETS: Final = frozenset({ChangeData.SUMMARY, ChangeData.INFO, ChangeData.SUPPLEMENT, ChangeData.OBJECTS})
COORD_WIDTH: Final = {ChangeData.POINTS: 2, ChangeData.LINES: 4}
"""int32 numbers per point / per segment."""
MAX_IN_PACKET: Final = {ChangeData.POINTS: 1000, ChangeData.LINES: 500}
"""ARIA's ``MAX_POINTS_IN_PACKET`` / ``MAX_LINES_IN_PACKET``: its reader takes exactly this many from
every packet but the last of a run, so a writer must fill them."""
CONTINUES: Final = -1
"""The count of a packet that carries on the previous packet's run."""
CHANGE_SUCCESS: Final = 10
CHANGE_FAILED: Final = 0
INFO_NAMES: Final = (
    "MapInfo:",
    "MetaInfo:",
    "TaskInfo:",
    "RouteInfo:",
    "SchedTaskInfo:",
    "SchedInfo:",
    "CairnInfo:",
    "CustomInfo:",
)
"""ARIA's default info sections, in the order an info index counts them."""
PACKET_ROOM: Final = MAX_PAYLOAD - 1000
"""A line set's packet is closed once another group would pass this (ARIA keeps 1000 bytes spare)."""
NULL_MAP_ID: Final = MapId("", "", b"", 0, -1)


@dataclass(frozen=True, slots=True)
class FileLine:
    """A map file line and its line number (ARIA's ``ArMapFileLine``)."""

    number: int
    text: str


@dataclass(frozen=True, slots=True)
class FileLineGroup:
    """A line and the lines that belong to it (``RouteInfo:`` tasks); objects have no children."""

    parent: FileLine
    children: tuple[FileLine, ...] = ()

    def size(self) -> int:
        """Bytes it takes in a packet."""
        return 9 + len(self.parent.text) + sum(5 + len(c.text) for c in self.children)


@register
@dataclass(frozen=True, slots=True)
class MapChangePacket(Payload):
    """One ``processMapChanges`` packet of a series (see the module's text for the layout).

    ``total`` is the group / point / segment count of the whole run, or :data:`CONTINUES`. A group
    whose children run on into the next packet (ARIA's writer can do that for a group of more than
    ~30 KB) is refused as malformed: RTMU writes whole groups and reads only those.
    """

    DATA_NAME = "processMapChanges"
    SIDE = Side.ARGS

    command: ChangeCommand
    orig_id: MapId = NULL_MAP_ID
    new_id: MapId = NULL_MAP_ID
    data: ChangeData = ChangeData.NONE
    change: LineChange = LineChange.ADDITIONS
    scan_type: str = ""
    info_index: int = -1
    total: int = CONTINUES
    groups: tuple[FileLineGroup, ...] = ()
    coords: bytes = b""
    """Points or segments: little-endian int32 ``x y`` / ``x1 y1 x2 y2``."""

    @property
    def count(self) -> int:
        """Points or segments in this packet."""
        width = COORD_WIDTH.get(self.data)
        return len(self.coords) // (4 * width) if width else 0

    @property
    def array(self) -> np.ndarray:
        """This packet's points ``(n, 2)`` or segments ``(n, 4)`` as a read-only int32 view."""
        width = COORD_WIDTH.get(self.data, 2)
        return np.frombuffer(self.coords, COORD_DTYPE).reshape(-1, width)

    def encode(self) -> bytes:
        w = FieldWriter().ubyte2(self.command)
        self.orig_id.write(w)
        self.new_id.write(w)
        if self.command is not ChangeCommand.CONTINUE:
            return w.bytes()
        w.ubyte(self.data).ubyte(self.change).string(self.scan_type)
        if self.data in LINE_SETS:
            w.byte4(self.info_index).byte4(self.total)
            for g in self.groups:
                w.byte4(len(g.children)).byte4(g.parent.number).string(g.parent.text)
                for child in g.children:
                    w.byte4(child.number).string(child.text)
        elif self.data in COORD_WIDTH:
            w.byte4(self.total).raw(self.coords)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        value = r.ubyte2("change command")
        if value > ChangeCommand.CANCEL:
            raise PayloadError(f"processMapChanges: unknown change command {value}")
        command = ChangeCommand(value)
        orig, new = MapId.read(r), MapId.read(r)
        if command is not ChangeCommand.CONTINUE:
            return cls(command, orig, new)
        kind, change = r.ubyte("change data type"), r.ubyte("change type")
        if kind > ChangeData.LINES:
            raise PayloadError(f"processMapChanges: unknown change data type {kind}")
        if change > LineChange.ADDITIONS:
            raise PayloadError(f"processMapChanges: unknown change type {change}")
        what = ChangeData(kind)
        base = cls(command, orig, new, what, LineChange(change), r.string("scan type"))
        if what in LINE_SETS:
            info_index, total = r.byte4("info index"), _total(r.byte4("group count"), "group count")
            return replace(base, info_index=info_index, total=total, groups=_read_groups(r))
        if what in COORD_WIDTH:
            total = _total(r.byte4("count"), "point or segment count")
            rest = r.rest()
            size = 4 * COORD_WIDTH[what]
            if len(rest) % size or len(rest) // size > MAX_IN_PACKET[what]:
                raise PayloadError(
                    f"processMapChanges: {len(rest)} bytes is not a whole number of up to "
                    f"{MAX_IN_PACKET[what]} {what.name.lower()} of {size} bytes"
                )
            return replace(base, total=total, coords=rest)
        return base


def _total(value: int, what: str) -> int:
    if value == 0 or value < CONTINUES:
        raise PayloadError(f"processMapChanges: {what} {value} (a run has at least one item; -1 continues)")
    return value


def _read_groups(r: FieldReader) -> tuple[FileLineGroup, ...]:
    groups: list[FileLineGroup] = []
    while not r.at_end():
        children = r.byte4("child count")
        if children < 0:
            raise PayloadError("processMapChanges: child lines continued from another packet are not read")
        parent = FileLine(r.byte4("line number"), r.string("line"))
        checked_count(children, 5, r, "child lines")
        kids = tuple(FileLine(r.byte4("child line number"), r.string("child line")) for _ in range(children))
        groups.append(FileLineGroup(parent, kids))
    return tuple(groups)


@register
@dataclass(frozen=True, slots=True)
class MapChangeReply(Payload):
    """``processMapChanges`` reply to a finish or cancel: ``ubyte2`` 10 applied, 0 refused."""

    DATA_NAME = "processMapChanges"
    SIDE = Side.REPLY

    status: int

    @property
    def accepted(self) -> bool:
        return self.status == CHANGE_SUCCESS

    def encode(self) -> bytes:
        return FieldWriter().ubyte2(self.status).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(FieldReader(data).ubyte2("change status"))


@register
@dataclass(frozen=True, slots=True)
class MapChangesInProgress(SingleFlag):
    """``mapChangesInProgress`` broadcast: 1 while a client's change set is open, 0 after its verdict."""

    DATA_NAME = "mapChangesInProgress"
    SIDE = Side.REPLY
    FIELD_KIND = "ubyte"
    FIELD_LABEL = "in progress"

    in_progress: bool


# -- whole change sets --------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class LineSetChange:
    """Lines of one kind added or deleted: map objects (``Cairn: …``), info, summary or supplement lines."""

    data: ChangeData
    change: LineChange
    groups: tuple[FileLineGroup, ...]
    scan_type: str = ""
    info_index: int = -1


@dataclass(frozen=True, slots=True)
class CoordChange:
    """Points ``(n, 2)`` or segments ``(n, 4)`` of one scan added or deleted (int32 mm)."""

    data: ChangeData
    change: LineChange
    coords: np.ndarray
    scan_type: str = ""


@dataclass(frozen=True, slots=True)
class MapChangeSet:
    """Everything one ``processMapChanges`` series carries."""

    line_sets: tuple[LineSetChange, ...] = ()
    coord_sets: tuple[CoordChange, ...] = ()
    orig_id: MapId = NULL_MAP_ID
    new_id: MapId = NULL_MAP_ID

    def lines(self, data: ChangeData, change: LineChange) -> list[str]:
        """The parent lines of every group of this kind (e.g. the objects added)."""
        return [
            g.parent.text for s in self.line_sets if (s.data, s.change) == (data, change) for g in s.groups
        ]

    def coords(self, data: ChangeData, change: LineChange, scan_type: str = "") -> np.ndarray:
        width = COORD_WIDTH[data]
        parts = [
            c.coords for c in self.coord_sets if (c.data, c.change, c.scan_type) == (data, change, scan_type)
        ]
        return np.concatenate(parts) if parts else np.zeros((0, width), np.int32)

    @property
    def empty(self) -> bool:
        return not any(s.groups for s in self.line_sets) and not any(len(c.coords) for c in self.coord_sets)


def change_packets(changes: MapChangeSet, guard: MapId | None = None) -> list[MapChangePacket]:
    """The series for ``changes`` in ARIA's order: start; per change type (deletions first) summary,
    supplement, info, objects, points, segments; finish.

    ``guard``: the id of the map the change was made against. The start packet carries the set's own
    ids; every other packet carries ``guard`` twice, so the server refuses the set if its map is no
    longer that one (see the module's text).
    """
    ids = (guard, guard) if guard is not None else (changes.orig_id, changes.new_id)
    out = [MapChangePacket(ChangeCommand.START, changes.orig_id, changes.new_id)]
    order = (ChangeData.SUMMARY, ChangeData.SUPPLEMENT, ChangeData.INFO, ChangeData.OBJECTS)
    for change in LineChange:
        for data in order:
            for s in changes.line_sets:
                if (s.data, s.change) == (data, change) and s.groups:
                    out += _line_set_packets(s, ids)
        for data in (ChangeData.POINTS, ChangeData.LINES):
            for c in changes.coord_sets:
                if (c.data, c.change) == (data, change) and len(c.coords):
                    out += _coord_packets(c, ids)
    out.append(MapChangePacket(ChangeCommand.FINISH, *ids))
    return out


def _line_set_packets(s: LineSetChange, ids: tuple[MapId, MapId]) -> list[MapChangePacket]:
    head = MapChangePacket(ChangeCommand.CONTINUE, *ids, s.data, s.change, s.scan_type, s.info_index)
    room = PACKET_ROOM - len(head.encode())
    out: list[MapChangePacket] = []
    batch: list[FileLineGroup] = []
    size = 0
    for g in s.groups:
        if g.size() > room:
            raise ValueError(f"a map line group of {g.size()} bytes does not fit in one packet")
        if batch and size + g.size() > room:
            out.append(replace(head, total=len(s.groups) if not out else CONTINUES, groups=tuple(batch)))
            batch, size = [], 0
        batch.append(g)
        size += g.size()
    out.append(replace(head, total=len(s.groups) if not out else CONTINUES, groups=tuple(batch)))
    return out


def _coord_packets(c: CoordChange, ids: tuple[MapId, MapId]) -> list[MapChangePacket]:
    width, per = COORD_WIDTH[c.data], MAX_IN_PACKET[c.data]
    raw = coords_bytes(np.asarray(c.coords).reshape(-1, width), width)
    step = per * width * 4
    head = MapChangePacket(ChangeCommand.CONTINUE, *ids, c.data, c.change, c.scan_type)
    return [
        replace(head, total=len(c.coords) if i == 0 else CONTINUES, coords=raw[i : i + step])
        for i in range(0, len(raw), step)
    ]


MAX_CHANGE_PACKETS: Final = 20_000
MAX_CHANGE_GROUPS: Final = 200_000
MAX_CHANGE_COORDS: Final = 4_000_000


@dataclass
class MapChangeAssembler:
    """Joins one client's series into a :class:`MapChangeSet`, checking it as ARIA's reader would.

    ``feed`` returns True at the finish (or cancel: :attr:`cancelled`); a series that breaks its own
    counts, or outgrows the bounds, raises :class:`PayloadError` and is of no further use.
    """

    max_packets: int = MAX_CHANGE_PACKETS
    max_groups: int = MAX_CHANGE_GROUPS
    max_coords: int = MAX_CHANGE_COORDS
    packets: int = 0
    cancelled: bool = False
    finished: bool = False
    orig_id: MapId = NULL_MAP_ID
    new_id: MapId = NULL_MAP_ID
    _line_sets: list[LineSetChange] = field(default_factory=list)
    _coord_sets: list[tuple[CoordChange, list[bytes]]] = field(default_factory=list)
    _run: tuple[ChangeData, LineChange, str, int] | None = None
    _left = 0
    _groups = 0
    _coords = 0

    def feed(self, packet: MapChangePacket) -> bool:
        if self.finished:
            raise PayloadError("processMapChanges: packets after the finish")
        self.packets += 1
        if self.packets > self.max_packets:
            raise PayloadError(f"processMapChanges: more than {self.max_packets} packets in one change set")
        if self.packets == 1 and packet.command is not ChangeCommand.START:
            raise PayloadError(
                f"processMapChanges: a change set starts with a start, not {packet.command.name}"
            )
        if packet.command is ChangeCommand.START:
            if self.packets != 1:
                raise PayloadError("processMapChanges: a second start inside one change set")
            self.orig_id, self.new_id = packet.orig_id, packet.new_id
            return False
        if packet.command in (ChangeCommand.FINISH, ChangeCommand.CANCEL):
            if packet.command is ChangeCommand.FINISH and self._left:
                raise PayloadError(f"processMapChanges: finished with {self._left} announced items missing")
            self.finished = True
            self.cancelled = packet.command is ChangeCommand.CANCEL
            return True
        self._continue(packet)
        return False

    def _continue(self, p: MapChangePacket) -> None:
        if p.data is ChangeData.NONE:
            return
        key = (p.data, p.change, p.scan_type, p.info_index)
        items = len(p.groups) if p.data in LINE_SETS else p.count
        if p.total == CONTINUES:
            if self._run != key or not self._left:
                raise PayloadError("processMapChanges: a continuing packet that continues nothing")
        else:
            if self._left:
                raise PayloadError(f"processMapChanges: a new run while {self._left} items are still due")
            self._run, self._left = key, p.total
            if p.data in LINE_SETS:
                self._line_sets.append(LineSetChange(p.data, p.change, (), p.scan_type, p.info_index))
            else:
                width = COORD_WIDTH[p.data]
                empty = np.zeros((0, width), np.int32)
                self._coord_sets.append((CoordChange(p.data, p.change, empty, p.scan_type), []))
        if p.data in COORD_WIDTH and items != min(self._left, MAX_IN_PACKET[p.data]):
            raise PayloadError(
                f"processMapChanges: {items} {p.data.name.lower()} in a packet where ARIA reads "
                f"{min(self._left, MAX_IN_PACKET[p.data])}"
            )
        if items > self._left:
            raise PayloadError(f"processMapChanges: {items} items where {self._left} were announced")
        if not items:
            raise PayloadError("processMapChanges: a packet with nothing in it")
        self._left -= items
        if p.data in LINE_SETS:
            self._groups += items
            if self._groups > self.max_groups:
                raise PayloadError(f"processMapChanges: more than {self.max_groups} lines in one change set")
            last = self._line_sets[-1]
            self._line_sets[-1] = replace(last, groups=last.groups + p.groups)
        else:
            self._coords += items
            if self._coords > self.max_coords:
                raise PayloadError(
                    f"processMapChanges: more than {self.max_coords} points and segments in one change set"
                )
            self._coord_sets[-1][1].append(p.coords)

    def result(self) -> MapChangeSet:
        if not self.finished:
            raise PayloadError("processMapChanges: the change set is not finished")
        coords = tuple(
            replace(c, coords=np.frombuffer(b"".join(parts), COORD_DTYPE).reshape(-1, COORD_WIDTH[c.data]))
            for c, parts in self._coord_sets
        )
        return MapChangeSet(tuple(self._line_sets), coords, self.orig_id, self.new_id)


__all__ = [
    "CHANGE_FAILED",
    "CHANGE_SUCCESS",
    "INFO_NAMES",
    "NULL_MAP_ID",
    "ChangeCommand",
    "ChangeData",
    "CoordChange",
    "FileLine",
    "FileLineGroup",
    "LineChange",
    "LineSetChange",
    "MapChangeAssembler",
    "MapChangePacket",
    "MapChangeReply",
    "MapChangeSet",
    "MapChangesInProgress",
    "change_packets",
]

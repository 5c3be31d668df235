"""Map data (protocol §4.5): name, id, goals, and the packets of the two map streams.

``getMap`` sends one text line per packet; ``getMapBinary`` sends the header as
text and the geometry as binary blocks of little-endian ``int32`` millimetres.
The types here decode one packet each; :mod:`.mapstream` assembles whole maps
and builds the server's packet series.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from enum import Enum
from typing import Final, Self

import numpy as np

from ..errors import FieldUnderrun, PayloadError
from ..fields import FieldReader, FieldWriter
from .base import EmptyPayload, Payload, Side, SingleField, checked_count, read_strings_to_end, register

SEGMENT_BYTES: Final = 16
"""``byte4 x1, y1, x2, y2``."""
POINT_BYTES: Final = 8
"""``byte4 x, y``."""
_COUNT = struct.Struct("<i")
COORD_DTYPE: Final = np.dtype("<i4")


@register
@dataclass(frozen=True, slots=True)
class MapName(SingleField):
    """``getMapName`` reply: the map file as the server configured it (may be a full path)."""

    DATA_NAME = "getMapName"
    SIDE = Side.REPLY
    FIELD_KIND = "string"
    FIELD_LABEL = "map file name"

    file_name: str
    """``""`` when the server has no map."""


@register
@dataclass(frozen=True, slots=True)
class MapId(Payload):
    """``getMapId`` reply (``ArMapId::toPacket``): enough to tell whether a cached map is current."""

    DATA_NAME = "getMapId"
    SIDE = Side.REPLY

    source_name: str
    file_name: str
    checksum: bytes
    """MD5 of the file (16 bytes), or empty when the server has checksums disabled."""
    size: int
    """File size in bytes."""
    mtime: int
    """Modification time, Unix seconds."""

    def encode(self) -> bytes:
        return self.write(FieldWriter()).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls.read(FieldReader(data))

    def write(self, w: FieldWriter) -> FieldWriter:
        """The id's fields into ``w`` (``processMapChanges`` carries two ids inside its own packet)."""
        w.string(self.source_name).string(self.file_name).ubyte4(len(self.checksum)).raw(self.checksum)
        return w.ubyte4(self.size).byte4(self.mtime)

    @classmethod
    def read(cls, r: FieldReader) -> Self:
        source = r.string("source name")
        name = r.string("file name")
        length = checked_count(r.ubyte4("checksum length"), 1, r, "checksum length")
        checksum = r.raw(length, "checksum")
        return cls(source, name, checksum, r.ubyte4("file size"), r.byte4("modification time"))

    @property
    def is_null(self) -> bool:
        """No source and no file name: ARIA's "null" id (a change set that names no map)."""
        return not self.source_name and not self.file_name

    def to_fields(self) -> dict[str, object]:
        out = Payload.to_fields(self)
        out["checksum"] = self.checksum.hex()
        return out


@register
@dataclass(frozen=True, slots=True)
class Goals(Payload):
    """``getGoals`` reply: goal names with no count (an empty payload = no goals)."""

    DATA_NAME = "getGoals"
    SIDE = Side.REPLY

    goals: tuple[str, ...] = ()

    def encode(self) -> bytes:
        w = FieldWriter()
        for g in self.goals:
            w.string(g)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(read_strings_to_end(FieldReader(data), "goal name"))


@register
@dataclass(frozen=True, slots=True)
class MapUpdated(EmptyPayload):
    """``mapUpdated`` broadcast (empty): the server changed its map; fetch it again."""

    DATA_NAME = "mapUpdated"
    SIDE = Side.REPLY


@register
@dataclass(frozen=True, slots=True)
class GoalsUpdated(EmptyPayload):
    """``goalsUpdated`` broadcast (empty): the goal list changed; ask ``getGoals`` again."""

    DATA_NAME = "goalsUpdated"
    SIDE = Side.REPLY


@register
@dataclass(frozen=True, slots=True)
class MapTextPacket(Payload):
    """One ``getMap`` reply packet: a map line, the end-of-map ``""``, or the zero-length end of reply."""

    DATA_NAME = "getMap"
    SIDE = Side.REPLY

    line: str | None
    """A map line; ``""`` ends the map (alone, it means "no map"); None is the zero-length packet."""

    @property
    def end_of_map(self) -> bool:
        return self.line == ""

    @property
    def end_of_reply(self) -> bool:
        return self.line is None

    def encode(self) -> bytes:
        return b"" if self.line is None else FieldWriter().string(self.line).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        if not data:
            return cls(None)
        return cls(FieldReader(data).string("map line"))


class MapPacketKind(Enum):
    TEXT = "text"
    """A header line, a section keyword (``LINES``, ``DATA``), or ``""`` (no map / no points)."""
    SEGMENTS = "segments"
    """``byte4 count`` + count × (x1, y1, x2, y2)."""
    POINTS = "points"
    """``byte4 count`` + count × (x, y)."""
    BLOCK_END = "block_end"
    """``byte4 0``: the end of a run of binary blocks."""
    END_OF_REPLY = "end_of_reply"
    """The zero-length packet."""


def binary_block_kind(data: bytes) -> MapPacketKind | None:
    """Which binary block ``data`` is, judged by its count and length alone; None if not binary.

    Unambiguous for ARIA's streams: a text packet holds one NUL-terminated
    string, so its first four bytes can never form a count whose blocks fill
    exactly the rest of the packet.
    """
    if len(data) < 4:
        return None
    (count,) = _COUNT.unpack_from(data)
    if count == 0:
        return MapPacketKind.BLOCK_END if len(data) == 4 else None
    if count < 0:
        return None
    body = len(data) - 4
    if body == count * SEGMENT_BYTES:
        return MapPacketKind.SEGMENTS
    if body == count * POINT_BYTES:
        return MapPacketKind.POINTS
    return None


@register
@dataclass(frozen=True, slots=True)
class MapBinaryPacket(Payload):
    """One ``getMapBinary`` reply packet, whatever its kind (see :class:`MapPacketKind`).

    Coordinates stay as the wire's little-endian ``int32`` bytes (``coords``);
    :attr:`segments` / :attr:`points` view them as numpy arrays without a copy.
    """

    DATA_NAME = "getMapBinary"
    SIDE = Side.REPLY

    kind: MapPacketKind
    text: str = ""
    coords: bytes = b""

    def __post_init__(self) -> None:
        size = {MapPacketKind.SEGMENTS: SEGMENT_BYTES, MapPacketKind.POINTS: POINT_BYTES}.get(self.kind)
        if size is None:
            if self.coords:
                raise ValueError(f"a {self.kind.value} packet carries no coordinates")
        elif not self.coords or len(self.coords) % size:
            raise ValueError(f"{self.kind.value} coordinates must be a non-empty multiple of {size} bytes")

    # -- constructors the server side uses ---------------------------------------
    @classmethod
    def text_line(cls, text: str) -> Self:
        return cls(MapPacketKind.TEXT, text)

    @classmethod
    def segment_block(cls, segments: np.ndarray) -> Self:
        return cls(MapPacketKind.SEGMENTS, coords=coords_bytes(segments, 4))

    @classmethod
    def point_block(cls, points: np.ndarray) -> Self:
        return cls(MapPacketKind.POINTS, coords=coords_bytes(points, 2))

    @classmethod
    def block_end(cls) -> Self:
        return cls(MapPacketKind.BLOCK_END)

    @classmethod
    def end_of_reply(cls) -> Self:
        return cls(MapPacketKind.END_OF_REPLY)

    # -- views ---------------------------------------------------------------------
    @property
    def count(self) -> int:
        """Items in a binary block (0 for every other kind)."""
        if self.kind is MapPacketKind.SEGMENTS:
            return len(self.coords) // SEGMENT_BYTES
        if self.kind is MapPacketKind.POINTS:
            return len(self.coords) // POINT_BYTES
        return 0

    @property
    def segments(self) -> np.ndarray:
        """``(n, 4)`` int32 array ``x1, y1, x2, y2`` (read-only view)."""
        if self.kind is not MapPacketKind.SEGMENTS:
            return np.empty((0, 4), COORD_DTYPE)
        return np.frombuffer(self.coords, COORD_DTYPE).reshape(-1, 4)

    @property
    def points(self) -> np.ndarray:
        """``(n, 2)`` int32 array ``x, y`` (read-only view)."""
        if self.kind is not MapPacketKind.POINTS:
            return np.empty((0, 2), COORD_DTYPE)
        return np.frombuffer(self.coords, COORD_DTYPE).reshape(-1, 2)

    def encode(self) -> bytes:
        kind = self.kind
        if kind is MapPacketKind.TEXT:
            return FieldWriter().string(self.text).bytes()
        if kind is MapPacketKind.END_OF_REPLY:
            return b""
        return _COUNT.pack(self.count) + self.coords

    @classmethod
    def decode(cls, data: bytes) -> Self:
        data = bytes(data)
        if not data:
            return cls(MapPacketKind.END_OF_REPLY)
        kind = binary_block_kind(data)
        if kind is None:
            return cls(MapPacketKind.TEXT, FieldReader(data).string("map line"))
        return cls(kind, coords=data[4:])

    def to_fields(self) -> dict[str, object]:
        out: dict[str, object] = {"kind": self.kind.value}
        if self.kind is MapPacketKind.TEXT:
            out["text"] = self.text
        elif self.kind in (MapPacketKind.SEGMENTS, MapPacketKind.POINTS):
            out["count"] = self.count
            array = self.segments if self.kind is MapPacketKind.SEGMENTS else self.points
            out[self.kind.value] = array.tolist()
        return out


@register
@dataclass(frozen=True, slots=True)
class MapWithMaxCategoryPacket(MapBinaryPacket):
    """``getMapWithMaxCategory`` reply packet: laid out as ``getMapBinary`` (scan-prefixed keywords)."""

    DATA_NAME = "getMapWithMaxCategory"


@register
@dataclass(frozen=True, slots=True)
class MapMultiScansPacket(MapBinaryPacket):
    """``getMapMultiScans`` reply packet (deprecated ``2D-Map-Ex`` form of ``getMapWithMaxCategory``)."""

    DATA_NAME = "getMapMultiScans"


@register
@dataclass(frozen=True, slots=True)
class MapWithMaxCategoryRequest(SingleField):
    """``getMapWithMaxCategory`` args: ``""`` or ``2D-Map`` = ``getMapBinary``; ``2D-Map-Ex(2)`` add scans."""

    DATA_NAME = "getMapWithMaxCategory"
    SIDE = Side.ARGS
    FIELD_KIND = "string"
    FIELD_LABEL = "category"

    category: str = ""


def coords_bytes(array: object, columns: int) -> bytes:
    """Little-endian int32 bytes of an ``(n, columns)`` array; floats are rounded to whole mm."""
    a = np.asarray(array)
    if a.size == 0:
        return b""
    if a.ndim != 2 or a.shape[1] != columns:
        raise ValueError(f"expected an (n, {columns}) array, got shape {a.shape}")
    if a.dtype.kind == "f":
        a = np.rint(a)
    elif a.dtype.kind not in "iu":
        raise ValueError(f"coordinates must be numbers, got {a.dtype}")
    if a.size and (a.min() < -(2**31) or a.max() > 2**31 - 1):
        raise ValueError("a coordinate does not fit in a byte4")
    return a.astype(COORD_DTYPE, copy=False).tobytes()


def read_block(data: bytes, item_size: int, what: str) -> bytes:
    """The coordinate bytes of a binary block (possibly empty, for ``byte4 0``), checked against its count."""
    if len(data) < 4:
        raise FieldUnderrun(f"{what} count", 4, len(data))
    (count,) = _COUNT.unpack_from(data)
    if count < 0 or len(data) - 4 != count * item_size:
        raise PayloadError(
            f"{what} block claims {count} items of {item_size} bytes but carries {len(data) - 4} bytes"
        )
    return data[4:]

"""Range sensors and their drawings (protocol §4.4).

Readings are ``(x, y)`` positions in mm in the global (odometric/map) frame,
not ranges: the server has already placed them in the world.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from typing import Final, Self

from ..errors import PayloadError
from ..fields import FieldReader, FieldWriter
from .base import NameMatch, Payload, Side, checked_count, read_strings_to_end, register

NO_SUCH_SENSOR: Final = -1
_XY = struct.Struct("<ii")

Reading = tuple[int, int]


def _read_xy(reader: FieldReader, count: int, field: str) -> tuple[Reading, ...]:
    checked_count(count, _XY.size, reader, field)
    raw = reader.raw(count * _XY.size, field)
    return tuple(_XY.iter_unpack(raw))


def _write_xy(writer: FieldWriter, readings: tuple[Reading, ...]) -> None:
    try:
        writer.raw(b"".join(_XY.pack(x, y) for x, y in readings))
    except struct.error as exc:
        raise ValueError(f"a reading does not fit in byte4 x/y: {exc}") from exc


@register
@dataclass(frozen=True, slots=True)
class SensorList(Payload):
    """``getSensorList`` reply: the robot's range devices (``sonar``, ``sim_lms2xx_1``, …)."""

    DATA_NAME = "getSensorList"
    SIDE = Side.REPLY

    names: tuple[str, ...] = ()
    listed: bool = True
    """False when the server sent an empty payload (the robot has no device list)."""

    def encode(self) -> bytes:
        if not self.listed:
            return b""
        w = FieldWriter().byte2(len(self.names))
        for n in self.names:
            w.string(n)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        if not data:
            return cls((), listed=False)
        r = FieldReader(data)
        count = checked_count(r.byte2("sensor count"), 1, r, "sensor count")
        return cls(tuple(r.string("sensor name") for _ in range(count)))


@register
@dataclass(frozen=True, slots=True)
class SensorCurrentRequest(Payload):
    """``getSensorCurrent`` args: one or more sensor names; the server answers one packet per name."""

    DATA_NAME = "getSensorCurrent"
    SIDE = Side.ARGS

    names: tuple[str, ...]

    def encode(self) -> bytes:
        w = FieldWriter()
        for n in self.names:
            w.string(n)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(read_strings_to_end(FieldReader(data), "sensor name"))


@register
@dataclass(frozen=True, slots=True)
class SensorCumulativeRequest(SensorCurrentRequest):
    """``getSensorCumulative`` args: as ``getSensorCurrent``."""

    DATA_NAME = "getSensorCumulative"


@register
@dataclass(frozen=True, slots=True)
class SensorReadings(Payload):
    """``getSensorCurrent`` reply for one sensor: ``byte2`` count (−1 = no such sensor), name, readings."""

    DATA_NAME = "getSensorCurrent"
    SIDE = Side.REPLY

    name: str
    readings: tuple[Reading, ...] = ()
    exists: bool = True
    """False when the server has no sensor of that name (count −1 on the wire)."""

    def encode(self) -> bytes:
        if not self.exists:
            if self.readings:
                raise ValueError("a missing sensor has no readings")
            return FieldWriter().byte2(NO_SUCH_SENSOR).string(self.name).bytes()
        w = FieldWriter().byte2(len(self.readings)).string(self.name)
        _write_xy(w, self.readings)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        count = r.byte2("reading count")
        name = r.string("sensor name")
        if count == NO_SUCH_SENSOR:
            return cls(name, (), exists=False)
        if count < 0:
            raise PayloadError(f"reading count is negative ({count})")
        return cls(name, _read_xy(r, count, "readings"))


@register
@dataclass(frozen=True, slots=True)
class SensorCumulativeReadings(SensorReadings):
    """``getSensorCumulative`` reply: as ``getSensorCurrent``, from the longer-lived buffer."""

    DATA_NAME = "getSensorCumulative"


@register
@dataclass(frozen=True, slots=True)
class RangeDeviceReadings(Payload):
    """``<device>Current`` reply (e.g. ``sonarCurrent``): ``byte4`` count, then x/y pairs in mm."""

    DATA_NAME = "Current"
    SIDE = Side.REPLY
    NAME_MATCH = NameMatch.SUFFIX

    readings: tuple[Reading, ...] = ()

    def encode(self) -> bytes:
        w = FieldWriter().byte4(len(self.readings))
        _write_xy(w, self.readings)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(_read_xy(r, r.byte4("reading count"), "readings"))


@register
@dataclass(frozen=True, slots=True)
class RangeDeviceCumulative(RangeDeviceReadings):
    """``<device>Cumulative`` reply: as ``<device>Current``."""

    DATA_NAME = "Cumulative"


@dataclass(frozen=True, slots=True)
class Drawing:
    """How a client should draw one data (usually a range device's ``<device>Current``)."""

    name: str
    """The data to request, e.g. ``sonarCurrent``."""
    shape: str
    """``polyDots``, ``polyArrows``, ``polyLine``, ``polyPoints``, ``polySegments``…"""
    primary_color: int
    """0x00RRGGBB."""
    size: int
    """mm."""
    layer: int
    refresh_ms: int
    """Suggested polling period; 0 = don't poll."""
    secondary_color: int
    visibility: str = ""
    """e.g. ``DefaultOn`` (``getDrawingList`` only)."""

    def _write(self, w: FieldWriter, with_visibility: bool) -> None:
        w.string(self.name).string(self.shape).byte4(self.primary_color).byte4(self.size)
        w.byte4(self.layer).ubyte4(self.refresh_ms).byte4(self.secondary_color)
        if with_visibility:
            w.string(self.visibility)

    @classmethod
    def _read(cls, r: FieldReader, with_visibility: bool) -> Drawing:
        return cls(
            r.string("drawing name"),
            r.string("shape"),
            r.byte4("primary color"),
            r.byte4("size"),
            r.byte4("layer"),
            r.ubyte4("default refresh time"),
            r.byte4("secondary color"),
            r.string("visibility") if with_visibility else "",
        )


@register
@dataclass(frozen=True, slots=True)
class DrawingListPacket(Payload):
    """One ``getDrawingList`` reply packet: a drawing, or None for the zero-length packet ending the list."""

    DATA_NAME = "getDrawingList"
    SIDE = Side.REPLY

    drawing: Drawing | None

    @property
    def end_of_reply(self) -> bool:
        return self.drawing is None

    def encode(self) -> bytes:
        if self.drawing is None:
            return b""
        w = FieldWriter()
        self.drawing._write(w, True)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        if not data:
            return cls(None)
        return cls(Drawing._read(FieldReader(data), True))


@register
@dataclass(frozen=True, slots=True)
class DrawingList(Payload):
    """``listDrawings`` reply (deprecated): ``byte4`` count, then drawings without visibility."""

    DATA_NAME = "listDrawings"
    SIDE = Side.REPLY

    drawings: tuple[Drawing, ...] = ()

    def encode(self) -> bytes:
        w = FieldWriter().byte4(len(self.drawings))
        for d in self.drawings:
            d._write(w, False)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        count = checked_count(r.byte4("drawing count"), 22, r, "drawing count")
        return cls(tuple(Drawing._read(r, False) for _ in range(count)))

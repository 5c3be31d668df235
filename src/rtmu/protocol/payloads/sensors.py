"""Range sensors (protocol §4.4); how a client draws them is in :mod:`.drawings`.

Readings are ``(x, y)`` positions in mm in the global (odometric/map) frame,
not ranges: the server has already placed them in the world.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final, Self

from ..errors import PayloadError
from ..fields import FieldReader, FieldWriter
from .base import NameMatch, Payload, Side, checked_count, read_strings_to_end, read_xy, register, write_xy

NO_SUCH_SENSOR: Final = -1

Reading = tuple[int, int]


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
        write_xy(w, self.readings, "reading")
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
        return cls(name, read_xy(r, count, "readings"))


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
        write_xy(w, self.readings, "reading")
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(read_xy(r, r.byte4("reading count"), "readings"))


@register
@dataclass(frozen=True, slots=True)
class RangeDeviceCumulative(RangeDeviceReadings):
    """``<device>Cumulative`` reply: as ``<device>Current``."""

    DATA_NAME = "Cumulative"

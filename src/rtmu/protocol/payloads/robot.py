"""Robot state and modes (protocol §4.1–4.2): the status stream a client shows all the time.

Units stay those of the wire — millimetres, degrees, mm/s, deg/s — except the
battery, which travels as tenths and is held here as a float (volts, or percent
when ``batteryInfo`` says state of charge); it encodes back to the same tenths.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass
from operator import itemgetter
from typing import Final, Self

from ..errors import FieldUnderrun
from ..fields import FieldReader, FieldWriter
from .base import Payload, Side, SingleField, SingleFlag, checked_count, register

TEMPERATURE_UNKNOWN: Final = -128
"""ARIA's temperature byte when the robot does not report one."""
TEMPERATURE_NOT_REPORTED: Final = frozenset({TEMPERATURE_UNKNOWN, -127})
"""Bytes that mean "no temperature": ARIA's −128, and the −127 that MobileSim (a robot without the
sensor) sends. No robot runs at −127 °C, so reading it as a temperature would only mislead."""

_NUMBERS = struct.Struct("<hiihhhhb")
_NUMBER_FIELDS: Final = (
    ("battery", 0),
    ("x", 2),
    ("y", 6),
    ("th", 10),
    ("vel", 12),
    ("rot_vel", 14),
    ("lat_vel", 16),
    ("temperature", 18),
)
_NUMBER_SIZES: Final = (2, 4, 4, 2, 2, 2, 2, 1)


def _numbers_underrun(available: int) -> FieldUnderrun:
    for (name, offset), size in zip(_NUMBER_FIELDS, _NUMBER_SIZES, strict=True):
        if offset + size > available:
            return FieldUnderrun(name, size, max(0, available - offset))
    raise AssertionError("not an underrun")  # pragma: no cover


def battery_tenths(value: float) -> int:
    """The wire's ``round(10 × v)``, rounding halves away from zero as ARIA's ``roundInt`` does."""
    scaled = value * 10.0
    return int(math.copysign(math.floor(abs(scaled) + 0.5), scaled))


@register
@dataclass(frozen=True, init=False)
class UpdateNumbers(tuple, Payload):
    """``updateNumbers`` reply: the 19-byte status a client polls (e.g. every 100 ms).

    A frozen dataclass (fields, ``replace``, ``asdict``, equality with its own class only, repr)
    whose values live in a tuple: the decoder makes one per status packet of every robot, and a
    tuple is built in one C call where a slotted dataclass sets its fields one call each (half the
    status path's cost). The fields are read-only properties over the tuple's items.
    """

    __slots__ = ()

    DATA_NAME = "updateNumbers"
    SIDE = Side.REPLY

    battery: float
    """Volts, or state of charge in % (see :class:`BatteryInfo`); one decimal on the wire."""
    x: int
    """mm, truncated toward zero."""
    y: int
    th: int
    """Degrees, −179…180, counter-clockwise positive."""
    vel: int
    """mm/s."""
    rot_vel: int
    """deg/s."""
    lat_vel: int
    """mm/s (0 on non-holonomic robots)."""
    temperature: int = TEMPERATURE_UNKNOWN
    """°C; −128 (or MobileSim's −127) = unknown."""

    SIZE = _NUMBERS.size

    def __new__(
        cls,
        battery: float,
        x: int,
        y: int,
        th: int,
        vel: int,
        rot_vel: int,
        lat_vel: int,
        temperature: int = TEMPERATURE_UNKNOWN,
    ) -> Self:
        return _new_tuple(cls, (battery, x, y, th, vel, rot_vel, lat_vel, temperature))

    def __getnewargs__(self) -> tuple[float, int, int, int, int, int, int, int]:  # copy and pickle
        return tuple(self)

    @property
    def temperature_known(self) -> bool:
        return self.temperature not in TEMPERATURE_NOT_REPORTED

    def encode(self) -> bytes:
        return self._pack()

    def _pack(self) -> bytes:
        try:
            return _NUMBERS.pack(
                battery_tenths(self.battery),
                self.x,
                self.y,
                self.th,
                self.vel,
                self.rot_vel,
                self.lat_vel,
                self.temperature,
            )
        except struct.error as exc:
            raise ValueError(f"updateNumbers field out of range: {exc}") from exc

    @classmethod
    def decode(cls, data: bytes) -> Self:
        # Hot path (every status packet of every robot; a recording's by the hundred thousand): one
        # precompiled unpack, one tuple.
        try:
            b, x, y, th, v, rv, lv, t = _NUMBERS.unpack_from(data)
        except struct.error:  # fewer than 19 bytes (a short payload costs nothing on the good path)
            raise _numbers_underrun(len(data)) from None
        return _new_tuple(cls, (b / 10, x, y, th, v, rv, lv, t))

    @classmethod
    def read_from(cls, reader: FieldReader) -> Self:
        """Read the 19 bytes from inside a longer payload (``update``)."""
        if reader.remaining < cls.SIZE:
            available = reader.remaining
            raise _numbers_underrun(available)
        return cls.decode(reader.raw(cls.SIZE))


_new_tuple = tuple.__new__
for _index, (_name, _) in enumerate(_NUMBER_FIELDS):  # each field reads its item (C, no frame)
    setattr(UpdateNumbers, _name, property(itemgetter(_index), doc=f"``{_name}``, item {_index}."))


@register
@dataclass(frozen=True, slots=True)
class UpdateStrings(Payload):
    """``updateStrings`` reply/broadcast: status, mode string and extended status."""

    DATA_NAME = "updateStrings"
    SIDE = Side.REPLY

    status: str
    mode: str
    extended_status: str

    def encode(self) -> bytes:
        return FieldWriter().string(self.status).string(self.mode).string(self.extended_status).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(r.string("status"), r.string("mode"), r.string("extended status"))


@register
@dataclass(frozen=True, slots=True)
class Update(Payload):
    """``update`` reply (deprecated): status and mode strings, then the ``updateNumbers`` fields."""

    DATA_NAME = "update"
    SIDE = Side.REPLY

    status: str
    mode: str
    numbers: UpdateNumbers

    def encode(self) -> bytes:
        return FieldWriter().string(self.status).string(self.mode).raw(self.numbers.encode()).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        status = r.string("status")
        mode = r.string("mode")
        return cls(status, mode, UpdateNumbers.read_from(r))


@register
@dataclass(frozen=True, slots=True)
class BatteryInfo(Payload):
    """``batteryInfo`` reply: the thresholds, and whether battery figures are state of charge."""

    DATA_NAME = "batteryInfo"
    SIDE = Side.REPLY

    low_battery: float
    shutdown: float
    state_of_charge: bool = False
    """True: battery values (``updateNumbers.battery`` too) are % charge; False: volts (also when an
    older server leaves the flag out)."""

    def encode(self) -> bytes:
        return (
            FieldWriter()
            .double(self.low_battery)
            .double(self.shutdown)
            .ubyte(1 if self.state_of_charge else 0)
            .bytes()
        )

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(
            r.double("low battery"), r.double("shutdown"), r.ubyte("state of charge flag", default=0) != 0
        )


@register
@dataclass(frozen=True, slots=True)
class PhysicalInfo(Payload):
    """``physicalInfo`` reply: robot type and footprint (mm)."""

    DATA_NAME = "physicalInfo"
    SIDE = Side.REPLY

    robot_type: str
    robot_subtype: str
    width: int
    length_front: int
    """Centre to front, mm."""
    length_rear: int
    """Centre to rear, mm."""
    holonomic: bool = False
    """The robot has lateral motion."""

    def encode(self) -> bytes:
        return (
            FieldWriter()
            .string(self.robot_type)
            .string(self.robot_subtype)
            .byte2(self.width)
            .byte2(self.length_front)
            .byte2(self.length_rear)
            .byte(1 if self.holonomic else 0)
            .bytes()
        )

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(
            r.string("robot type"),
            r.string("robot subtype"),
            r.byte2("width"),
            r.byte2("length front"),
            r.byte2("length rear"),
            r.byte("has lateral motion") != 0,
        )


@register
@dataclass(frozen=True, slots=True)
class ActivityTimeInfo(SingleField):
    """``activityTimeInfo`` reply: seconds since the active mode last reported activity."""

    DATA_NAME = "activityTimeInfo"
    SIDE = Side.REPLY
    FIELD_KIND = "byte4"
    FIELD_LABEL = "seconds since activity"

    seconds: int
    """−1 when no mode is active."""


@register
@dataclass(frozen=True, slots=True)
class ModeInfo(Payload):
    """``getModeInfo`` reply/broadcast: the active mode's internal name (``stop``, ``ratioDrive``…)."""

    DATA_NAME = "getModeInfo"
    SIDE = Side.REPLY

    mode_name: str
    """``""`` when no mode is active."""
    locked: bool = False
    will_unlock_if_requested: bool = False

    def encode(self) -> bytes:
        return (
            FieldWriter()
            .string(self.mode_name)
            .ubyte(1 if self.locked else 0)
            .ubyte(1 if self.will_unlock_if_requested else 0)
            .bytes()
        )

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(r.string("mode name"), r.ubyte("locked") != 0, r.ubyte("will unlock if requested") != 0)


@dataclass(frozen=True, slots=True)
class ModeData:
    """One row of ``getModeDataList``: which mode a data name belongs to."""

    mode_name: str
    data_name: str


@register
@dataclass(frozen=True, slots=True)
class ModeDataList(Payload):
    """``getModeDataList`` reply: ``ubyte4`` count, then (mode name, data name) pairs."""

    DATA_NAME = "getModeDataList"
    SIDE = Side.REPLY

    entries: tuple[ModeData, ...] = ()

    def encode(self) -> bytes:
        w = FieldWriter().ubyte4(len(self.entries))
        for e in self.entries:
            w.string(e.mode_name).string(e.data_name)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        count = checked_count(r.ubyte4("mode data count"), 2, r, "mode data count")
        return cls(tuple(ModeData(r.string("mode name"), r.string("data name")) for _ in range(count)))


@register
@dataclass(frozen=True, slots=True)
class ModeBusyChanged(SingleFlag):
    """``modeBusyChanged`` reply/broadcast: whether the active mode is busy right now."""

    DATA_NAME = "modeBusyChanged"
    SIDE = Side.REPLY
    FIELD_KIND = "byte"
    FIELD_LABEL = "busy"

    busy: bool

"""Data that Omron LD robots (ARAM) offer beyond serverDemo: docking state, routes, speech, data store.

Laser scans need no type here: ``Laser_1Current`` / ``Laser_2Current`` are range-device drawings and
decode with :class:`~rtmu.protocol.payloads.sensors.RangeDeviceReadings` (``byte4`` count, then
``byte4`` x, ``byte4`` y per point, map mm), found by its ``Current`` suffix. Confirmed: public ROS
bridges for LD robots read ``Laser_1Current`` / ``Laser_2Current`` exactly so.

Confirmation of each layout:

* ``dockInfo`` / ``dockInfoChanged`` — confirmed from the data descriptions ARIA's docking mode
  registers (ubyte state, ubyte forced, ubyte2 seconds to shutdown) and a public ArNetworking
  example client that reads the broadcast in that order.
* ``getRoutes``, ``patrol``, ``gotoRouteGoal``, ``say``, ``DataStore_*`` — NOT confirmed against
  a published source: ARAM's route and data-store handlers are not public. We assume the plainest
  ArNetworking shapes, the same as ``getGoals`` / ``gotoGoal``: a route list is names with no
  count, a route or a text to speak is one string, a data-store value is one string. Each type
  below says so again.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from enum import IntEnum
from typing import Self

from ..fields import FieldReader, FieldWriter
from .base import NameMatch, Payload, Side, SingleField, read_strings_to_end, register


class DockState(IntEnum):
    UNDOCKED = 0
    DOCKING = 1
    DOCKED = 2
    UNDOCKING = 3

    @property
    def label(self) -> str:
        return self.name.capitalize()


@register
@dataclass(frozen=True, slots=True)
class DockInfo(Payload):
    """``dockInfo`` reply: ``ubyte`` state, ``ubyte`` forced, ``ubyte2`` seconds to shutdown (0 = none).

    A state outside 0–3 is kept as its number (a newer server may add states) rather than refused.
    """

    DATA_NAME = "dockInfo"
    SIDE = Side.REPLY

    state: int
    forced: bool = False
    """Docking was forced (the robot cannot undock now)."""
    seconds_to_shutdown: int = 0

    @property
    def state_label(self) -> str:
        try:
            return DockState(self.state).label
        except ValueError:
            return f"state {self.state}"

    def encode(self) -> bytes:
        w = FieldWriter().ubyte(self.state).ubyte(1 if self.forced else 0)
        return w.ubyte2(self.seconds_to_shutdown).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(r.ubyte("dock state"), r.ubyte("forced") != 0, r.ubyte2("seconds to shutdown"))


@register
@dataclass(frozen=True, slots=True)
class DockInfoChanged(DockInfo):
    """``dockInfoChanged`` broadcast: the same fields as ``dockInfo``."""

    DATA_NAME = "dockInfoChanged"


@register
@dataclass(frozen=True, slots=True)
class Routes(Payload):
    """``getRoutes`` reply: route names with no count, like ``getGoals`` (layout NOT confirmed)."""

    DATA_NAME = "getRoutes"
    SIDE = Side.REPLY

    routes: tuple[str, ...] = ()

    def encode(self) -> bytes:
        w = FieldWriter()
        for name in self.routes:
            w.string(name)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(read_strings_to_end(FieldReader(data), "route name"))


@register
@dataclass(frozen=True, slots=True)
class Patrol(SingleField):
    """``patrol`` args: one string, the route to patrol (layout NOT confirmed; as ``gotoGoal``)."""

    DATA_NAME = "patrol"
    SIDE = Side.ARGS
    FIELD_KIND = "string"
    FIELD_LABEL = "route name"

    route: str


@register
@dataclass(frozen=True, slots=True)
class GotoRouteGoal(SingleField):
    """``gotoRouteGoal`` args: one string, the goal to drive to (layout NOT confirmed; as ``gotoGoal``)."""

    DATA_NAME = "gotoRouteGoal"
    SIDE = Side.ARGS
    FIELD_KIND = "string"
    FIELD_LABEL = "goal name"

    goal: str


@register
@dataclass(frozen=True, slots=True)
class Say(SingleField):
    """``say`` args: one string, the text to speak (layout NOT confirmed)."""

    DATA_NAME = "say"
    SIDE = Side.ARGS
    FIELD_KIND = "string"
    FIELD_LABEL = "text"

    text: str


DATA_STORE_PREFIX = "DataStore_"


@register
@dataclass(frozen=True, slots=True)
class DataStoreValue(SingleField):
    """``DataStore_<item>`` reply: the item's value as one string (layout NOT confirmed).

    Found for any ``DataStore_…`` name by its prefix.
    """

    DATA_NAME = DATA_STORE_PREFIX
    SIDE = Side.REPLY
    NAME_MATCH = NameMatch.PREFIX
    FIELD_KIND = "string"
    FIELD_LABEL = "value"

    value: str


def data_store_label(data_name: str) -> str:
    """``DataStore_WiFi_Quality`` → ``WiFi Quality``, ``DataStore_WirelessQuality`` → ``Wireless
    Quality``: the name a person reads in the details table (a name without underscores is split
    where its words start)."""
    name = data_name.removeprefix(DATA_STORE_PREFIX)
    if "_" in name:
        return name.replace("_", " ")
    return _WORD_START.sub(" ", name)


_WORD_START = re.compile(r"(?<=[a-z0-9])(?=[A-Z])")

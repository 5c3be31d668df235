"""ARIA's central server (``ArCentralManager`` in ``switchServer``): the operators' list of robots and
the robots' switch (see ``docs/architecture.md``, "Central server").

Operators log in to the central server (port 7272) and read ``clientList``; they subscribe (interval
−1) to ``clientAdded`` / ``clientRemoved`` broadcasts. Every entry has the same five fields: the host
to reach the robot's forwarder on (empty: the central server's own host), the forwarded port, the
robot's name, a flags string (ARIA always sends it empty) and the robot's own address as the central
server sees it.

Robots log in to the central server's robot port (5000) as ordinary clients and ask ``switch`` once
with their identifier; the empty reply means "accepted": from then on the robot is the *server* on
that same socket (it sends a server INTRODUCTION) and the central server logs in to it as a client.
``centralServerHeartbeat`` (central → robot) and ``centralHeartbeat`` (robot's answer) carry nothing.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Self

from ..fields import FieldReader, FieldWriter
from .base import EmptyPayload, Payload, Side, SingleField, checked_count, register

ENTRY_MIN_BYTES = 6
"""Smallest wire size of one entry: four empty strings (1 byte each) and a ubyte2 port."""


@dataclass(frozen=True, slots=True)
class CentralEntry:
    """One robot as the central server lists it."""

    hostname: str
    """Where its forwarder listens; empty means the central server's own host."""
    port: int
    name: str
    flags: str = ""
    address: str = ""
    """The robot's IP address as the central server sees its switched connection."""

    def write(self, w: FieldWriter) -> FieldWriter:
        w.string(self.hostname).ubyte2(self.port).string(self.name)
        return w.string(self.flags).string(self.address)

    @classmethod
    def read(cls, r: FieldReader) -> CentralEntry:
        host, port, name = r.string("hostname"), r.ubyte2("port"), r.string("robot name")
        return cls(host, port, name, r.string("flags"), r.string("address"))


@register
@dataclass(frozen=True, slots=True)
class ClientList(Payload):
    """``clientList`` reply: ``ubyte2`` count, then count entries (only robots whose forwarder is up)."""

    DATA_NAME = "clientList"
    SIDE = Side.REPLY

    entries: tuple[CentralEntry, ...]

    def encode(self) -> bytes:
        w = FieldWriter().ubyte2(len(self.entries))
        for entry in self.entries:
            entry.write(w)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        count = checked_count(r.ubyte2("robot count"), ENTRY_MIN_BYTES, r, "robot count")
        return cls(tuple(CentralEntry.read(r) for _ in range(count)))


class _OneEntry(Payload):
    """A broadcast that carries one entry (added or removed)."""

    __slots__ = ()
    entry: CentralEntry

    def encode(self) -> bytes:
        return self.entry.write(FieldWriter()).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(CentralEntry.read(FieldReader(data)))  # type: ignore[call-arg]


@register
@dataclass(frozen=True, slots=True)
class ClientAdded(_OneEntry):
    """``clientAdded`` broadcast: a robot's forwarder is up and may be connected to."""

    DATA_NAME = "clientAdded"
    SIDE = Side.REPLY

    entry: CentralEntry


@register
@dataclass(frozen=True, slots=True)
class ClientRemoved(_OneEntry):
    """``clientRemoved`` broadcast: a robot left (its switched connection ended or timed out)."""

    DATA_NAME = "clientRemoved"
    SIDE = Side.REPLY

    entry: CentralEntry


@register
@dataclass(frozen=True, slots=True)
class SwitchRequest(SingleField):
    """``switch`` asked once by a robot: its identifier (empty: the central server names it by its IP)."""

    DATA_NAME = "switch"
    SIDE = Side.ARGS
    FIELD_KIND = "string"
    FIELD_LABEL = "robot name"

    robot_name: str


@register
@dataclass(frozen=True, slots=True)
class SwitchAccepted(EmptyPayload):
    """``switch`` reply: empty; after it the socket's direction is reversed."""

    DATA_NAME = "switch"
    SIDE = Side.REPLY


@register
@dataclass(frozen=True, slots=True)
class CentralServerHeartbeat(EmptyPayload):
    """``centralServerHeartbeat``: sent by the central server to a switched robot (the link lives)."""

    DATA_NAME = "centralServerHeartbeat"
    SIDE = Side.ARGS


@register
@dataclass(frozen=True, slots=True)
class CentralHeartbeat(EmptyPayload):
    """``centralHeartbeat`` reply: the robot's empty answer (ARIA sends it by TCP and UDP)."""

    DATA_NAME = "centralHeartbeat"
    SIDE = Side.REPLY

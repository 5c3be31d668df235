"""Built-in data of every server and the comm monitor (protocol §3.9, §4.11)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Self

from ..fields import FieldReader, FieldWriter
from .base import Payload, Side, register


@register
@dataclass(frozen=True, slots=True)
class IdleProcessingPending(Payload):
    """``idleProcessingPending`` reply/broadcast: the server holds idle-only requests for later."""

    DATA_NAME = "idleProcessingPending"
    SIDE = Side.REPLY

    pending: bool

    def encode(self) -> bytes:
        return FieldWriter().byte(1 if self.pending else 0).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(FieldReader(data).byte("pending") != 0)


@register
@dataclass(frozen=True, slots=True)
class RequestClientRestart(Payload):
    """``requestClientRestart`` broadcast: reconnect (reason 1 = the configuration changed)."""

    DATA_NAME = "requestClientRestart"
    SIDE = Side.REPLY

    reason: int
    text: str = ""

    def encode(self) -> bytes:
        return FieldWriter().byte(self.reason).string(self.text).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(r.byte("reason"), r.string("text"))


@register
@dataclass(frozen=True, slots=True)
class HeartbeatInterval(Payload):
    """``getHeartbeatInterval`` reply: ms between ``heartbeatTcp``/``heartbeatUdp`` broadcasts."""

    DATA_NAME = "getHeartbeatInterval"
    SIDE = Side.REPLY

    interval_ms: int

    def encode(self) -> bytes:
        return FieldWriter().ubyte4(self.interval_ms).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(FieldReader(data).ubyte4("heartbeat interval"))


@register
@dataclass(frozen=True, slots=True)
class HeartbeatTcp(Payload):
    """``heartbeatTcp`` broadcast (empty), to subscribers only."""

    DATA_NAME = "heartbeatTcp"
    SIDE = Side.REPLY

    def encode(self) -> bytes:
        return b""

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls()


@register
@dataclass(frozen=True, slots=True)
class HeartbeatUdp(HeartbeatTcp):
    """``heartbeatUdp`` broadcast (empty); a TCP-only client receives it over TCP."""

    DATA_NAME = "heartbeatUdp"


@register
@dataclass(frozen=True, slots=True)
class SelfIdentifier(Payload):
    """``identSetSelfIdentifier`` args: a free-form name for this client."""

    DATA_NAME = "identSetSelfIdentifier"
    SIDE = Side.ARGS

    identifier: str

    def encode(self) -> bytes:
        return FieldWriter().string(self.identifier).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(FieldReader(data).string("identifier"))

"""Built-in data of every server and the comm monitor (protocol §3.9, §4.11)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Self

from ..fields import FieldReader, FieldWriter
from .base import EmptyPayload, Payload, Side, SingleField, SingleFlag, register


@register
@dataclass(frozen=True, slots=True)
class IdleProcessingPending(SingleFlag):
    """``idleProcessingPending`` reply/broadcast: the server holds idle-only requests for later."""

    DATA_NAME = "idleProcessingPending"
    SIDE = Side.REPLY
    FIELD_KIND = "byte"
    FIELD_LABEL = "pending"

    pending: bool


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
class HeartbeatInterval(SingleField):
    """``getHeartbeatInterval`` reply: ms between ``heartbeatTcp``/``heartbeatUdp`` broadcasts."""

    DATA_NAME = "getHeartbeatInterval"
    SIDE = Side.REPLY
    FIELD_KIND = "ubyte4"
    FIELD_LABEL = "heartbeat interval"

    interval_ms: int


@register
@dataclass(frozen=True, slots=True)
class HeartbeatTcp(EmptyPayload):
    """``heartbeatTcp`` broadcast (empty), to subscribers only."""

    DATA_NAME = "heartbeatTcp"
    SIDE = Side.REPLY


@register
@dataclass(frozen=True, slots=True)
class HeartbeatUdp(HeartbeatTcp):
    """``heartbeatUdp`` broadcast (empty); a TCP-only client receives it over TCP."""

    DATA_NAME = "heartbeatUdp"


@register
@dataclass(frozen=True, slots=True)
class SelfIdentifier(SingleField):
    """``identSetSelfIdentifier`` args: a free-form name for this client."""

    DATA_NAME = "identSetSelfIdentifier"
    SIDE = Side.ARGS
    FIELD_KIND = "string"
    FIELD_LABEL = "identifier"

    identifier: str

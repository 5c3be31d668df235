"""Configuration care (``ArServerHandlerConfig``): factory values, one-parameter sets, reload, ``checkMap``.

* ``getConfigDefaults`` — offered only by a server that loaded a defaults file. Args: an optional
  ``string`` section ("" or nothing: all of them). Reply: ONE packet of text pairs in ``setConfig``'s
  form — ``("Section", name)`` then ``(parameter, value)`` per parameter (lists and separators send
  an empty value) — or an empty packet when the server has no defaults. ``configDefaultsUpdated``
  (empty) is broadcast when the defaults are read again.
* ``setConfigParam`` — args as ``setConfig``; the reply is ``string`` the last section named, then
  ``string`` the first error ("" = taken). A server that prevents changes answers its one reason
  string instead (and sends the asker ``configUpdated``).
* ``reloadConfig`` — no args and, although listed RETURN_SINGLE, no reply: the server reads its file
  again and broadcasts ``configUpdated`` to everyone, the asker too.
* ``checkMap`` — no args, no reply: re-read the map file if it changed (then ``mapUpdated``).

The three requests that change something are IDLE_PACKET data: ARIA runs them once the robot has been
still for a second (``idleProcessingPending`` says when they wait).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Self

from ..fields import FieldReader, FieldWriter
from .base import EmptyPayload, Payload, Side, register
from .config import SetConfig


@register
@dataclass(frozen=True, slots=True)
class ConfigDefaultsRequest(Payload):
    """``getConfigDefaults`` args: one section's defaults, or ("") all of them."""

    DATA_NAME = "getConfigDefaults"
    SIDE = Side.ARGS

    section: str = ""

    def encode(self) -> bytes:
        return FieldWriter().string(self.section).bytes() if self.section else b""

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(FieldReader(data).string("section", ""))


@register
@dataclass(frozen=True, slots=True)
class ConfigDefaults(SetConfig):
    """``getConfigDefaults`` reply: the factory values as ``(name, value)`` pairs, sections by ``Section``.

    Empty when the server has no defaults; :meth:`SetConfig.by_section` lists ``(section, name, value)``.
    """

    DATA_NAME = "getConfigDefaults"
    SIDE = Side.REPLY


@register
@dataclass(frozen=True, slots=True)
class ConfigDefaultsUpdated(EmptyPayload):
    """``configDefaultsUpdated`` broadcast: the server read its defaults again."""

    DATA_NAME = "configDefaultsUpdated"
    SIDE = Side.REPLY


@register
@dataclass(frozen=True, slots=True)
class SetConfigParam(SetConfig):
    """``setConfigParam`` args: ``("Section", name)`` and ``(parameter, value text)`` pairs."""

    DATA_NAME = "setConfigParam"
    SIDE = Side.ARGS


@register
@dataclass(frozen=True, slots=True)
class SetConfigParamReply(Payload):
    """``setConfigParam`` reply: the last section named and the first error ("" = every value taken).

    A server that prevents changes answers one string, its reason: read as ``error`` with no section.
    """

    DATA_NAME = "setConfigParam"
    SIDE = Side.REPLY

    section: str = ""
    error: str = ""

    @property
    def accepted(self) -> bool:
        return not self.error

    def encode(self) -> bytes:
        return FieldWriter().string(self.section).string(self.error).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        first = r.string("section", "")
        if r.at_end():
            return cls("", first) if first else cls()
        return cls(first, r.string("error", ""))


@register
@dataclass(frozen=True, slots=True)
class ReloadConfig(EmptyPayload):
    """``reloadConfig`` args (none): read the configuration file again; ``configUpdated`` follows."""

    DATA_NAME = "reloadConfig"
    SIDE = Side.ARGS


@register
@dataclass(frozen=True, slots=True)
class CheckMap(EmptyPayload):
    """``checkMap`` args (none): re-read the map file if it changed; ``mapUpdated`` follows if it did."""

    DATA_NAME = "checkMap"
    SIDE = Side.ARGS


__all__ = [
    "CheckMap",
    "ConfigDefaults",
    "ConfigDefaultsRequest",
    "ConfigDefaultsUpdated",
    "ReloadConfig",
    "SetConfigParam",
    "SetConfigParamReply",
]

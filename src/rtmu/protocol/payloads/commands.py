"""Simple commands (protocol §4.10): lists of names that are themselves data names.

A listed plain command is invoked by a request-once with an empty payload; a
string command with one string argument (:class:`StringCommandArgs`). Their
names vary by server, so those args are not registered under a data name.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Self

from ..fields import FieldReader, FieldWriter
from .base import Payload, Side, SingleField, checked_count, register


@dataclass(frozen=True, slots=True)
class CommandEntry:
    name: str
    """The data name to invoke."""
    description: str


@register
@dataclass(frozen=True, slots=True)
class CommandList(Payload):
    """``listCommands`` reply: ``byte2`` count, then (name, description)."""

    DATA_NAME = "listCommands"
    SIDE = Side.REPLY

    commands: tuple[CommandEntry, ...] = ()

    def encode(self) -> bytes:
        w = FieldWriter().byte2(len(self.commands))
        for c in self.commands:
            w.string(c.name).string(c.description)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        count = checked_count(r.byte2("command count"), 2, r, "command count")
        return cls(
            tuple(CommandEntry(r.string("command name"), r.string("description")) for _ in range(count))
        )


@register
@dataclass(frozen=True, slots=True)
class StringCommandList(CommandList):
    """``listStringCommands`` reply: as ``listCommands``; these take one string argument."""

    DATA_NAME = "listStringCommands"


@dataclass(frozen=True, slots=True)
class StringCommandArgs(SingleField):
    """The argument of a listed string command (the server splits it into words).

    Not registered: each string command is its own data name.
    """

    DATA_NAME = ""
    SIDE = Side.ARGS
    FIELD_KIND = "string"
    FIELD_LABEL = "argument"

    argument: str

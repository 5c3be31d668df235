"""The server's configuration (ArConfig) over ArNetworking: read it by sections, set values, follow changes.

``getConfigBySections`` (and its V2–V4) answer with one packet per section — or per part of a
section too big for one packet (V3+) — and then an empty packet. A section packet is ``'S'``,
the section's name and comment (V2+: its category; V3+: a ``ubyte2`` part index), then
``'P'`` + one parameter, repeated to the end of the packet. A parameter is its name,
description, priority byte and type letter (lower case: a display hint follows), the value
(with limits for numbers; V2+ a double's precision), the display hint (``Choices:a;;b``),
V2+ the extra explanation and restart level, V4+ a "serializable" byte and a parent path.

``setConfig`` sends ``(name, value)`` text pairs, ``("Section", name)`` choosing the section of
the pairs after it; the reply is one string, empty when every value was taken, otherwise the
first error. A server then broadcasts ``configUpdated`` (empty) to the *other* clients.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum, IntEnum
from typing import ClassVar, Self

from ..errors import PayloadError
from ..fields import FieldReader, FieldWriter
from .base import EmptyPayload, Payload, Side, checked_count, register

MAX_LIST_DEPTH = 4
"""Lists inside lists deeper than this are refused (ARIA's own lists are one or two deep)."""
CHOICES_PREFIX = "Choices:"
CHOICES_SEPARATOR = ";;"
SECTION_TAG = "Section"
"""The name that, in ``setConfig`` pairs, names the section of the pairs after it."""


class Priority(IntEnum):
    """``ArPriority::Priority``: who is expected to change a parameter (higher = more expert)."""

    BASIC = 0
    INTERMEDIATE = 1
    ADVANCED = 2
    EXPERT = 3
    FACTORY = 4

    @classmethod
    def of(cls, value: int) -> Priority:
        """A wire byte as a priority; past the last one counts as FACTORY (as ARIA clamps it)."""
        return cls(min(max(value, 0), cls.FACTORY))


class Restart(IntEnum):
    """``ArConfigArg::RestartLevel``: what must restart for a change to take effect."""

    NONE = 0
    CLIENT = 1
    IO = 2
    SOFTWARE = 3
    HARDWARE = 4


class ParamType(Enum):
    """The type letter of a parameter (upper case on the wire when no display hint follows)."""

    BOOL = "b"
    INT = "i"
    DOUBLE = "d"
    STRING = "s"
    LIST = "l"
    SEPARATOR = "."


Value = bool | int | float | str | None


@dataclass(frozen=True, slots=True)
class ConfigParam:
    """One parameter as the server describes it. Separators and lists have no value of their own."""

    name: str
    kind: ParamType
    value: Value = None
    description: str = ""
    priority: int = Priority.BASIC
    minimum: int | float | None = None
    """INT/DOUBLE only (ARIA sends its INT_MIN / -INF when unlimited)."""
    maximum: int | float | None = None
    precision: int = -1
    """DOUBLE only (V2+): digits after the point the server keeps; -1 = not said."""
    children: tuple[ConfigParam, ...] = ()
    """LIST only: its members, each a parameter."""
    display_hint: str = ""
    extra: str = ""
    """The longer explanation (V2+)."""
    restart: int = Restart.NONE
    serializable: bool = False
    parent_path: str = ""

    @property
    def choices(self) -> tuple[str, ...]:
        """The values a ``Choices:a;;b`` display hint allows (empty: any value of the type)."""
        if not self.display_hint.startswith(CHOICES_PREFIX):
            return ()
        return tuple(c for c in self.display_hint[len(CHOICES_PREFIX) :].split(CHOICES_SEPARATOR) if c)

    def value_text(self) -> str:
        """The value as ``setConfig`` and a config file write it."""
        return value_text(self.kind, self.value)

    def write(self, w: FieldWriter, version: int) -> None:
        w.string(self.name).string(self.description).byte(self.priority)
        w.byte(ord(self.kind.value))
        v = self.value
        if self.kind is ParamType.BOOL:
            w.byte(1 if v else 0)
        elif self.kind is ParamType.INT:
            w.byte4(int(v or 0)).byte4(int(self.minimum or 0)).byte4(int(self.maximum or 0))
        elif self.kind is ParamType.DOUBLE:
            w.double(float(v or 0.0)).double(_num(self.minimum)).double(_num(self.maximum))
            if version >= 2:
                w.byte4(self.precision)
        elif self.kind is ParamType.STRING:
            w.string(str(v or ""))
        elif self.kind is ParamType.LIST:
            w.byte4(len(self.children))
            for child in self.children:
                child.write(w, version)
        w.string(self.display_hint)
        if version >= 2:
            w.string(self.extra).byte(self.restart)
        if version >= 4:
            w.ubyte(1 if self.serializable else 0).string(self.parent_path)

    @classmethod
    def read(cls, r: FieldReader, version: int, depth: int = 0) -> ConfigParam:
        name = r.string("parameter name")
        description = r.string(f"{name} description")
        priority = r.byte(f"{name} priority")
        letter = r.ubyte(f"{name} type")
        try:
            kind = ParamType(chr(letter).lower())
        except ValueError:
            raise PayloadError(f"parameter {name!r} has an unknown type {chr(letter)!r}") from None
        hinted = kind is ParamType.SEPARATOR or chr(letter).islower()
        value: Value = None
        minimum: int | float | None = None
        maximum: int | float | None = None
        precision = -1
        children: tuple[ConfigParam, ...] = ()
        if kind is ParamType.BOOL:
            value = r.byte(f"{name} value") != 0
        elif kind is ParamType.INT:
            value, minimum, maximum = r.byte4(f"{name} value"), r.byte4(f"{name} min"), r.byte4(f"{name} max")
        elif kind is ParamType.DOUBLE:
            value, minimum = r.double(f"{name} value"), r.double(f"{name} min")
            maximum = r.double(f"{name} max")
            if version >= 2:
                precision = r.byte4(f"{name} precision")
        elif kind is ParamType.STRING:
            value = r.string(f"{name} value")
        elif kind is ParamType.LIST:
            if depth >= MAX_LIST_DEPTH:
                raise PayloadError(f"list {name!r} nests deeper than {MAX_LIST_DEPTH} lists")
            count = checked_count(r.byte4(f"{name} member count"), 5, r, f"{name} members")
            children = tuple(cls.read(r, version, depth + 1) for _ in range(count))
        hint = r.string(f"{name} display hint") if hinted else ""
        extra, restart, serializable, parent = "", 0, False, ""
        if version >= 2:
            extra, restart = r.string(f"{name} explanation"), r.byte(f"{name} restart level")
        if version >= 4:
            serializable, parent = r.ubyte(f"{name} serializable") != 0, r.string(f"{name} parent path")
        return cls(
            name, kind, value, description, priority, minimum, maximum, precision, children,
            hint, extra, restart, serializable, parent,
        )  # fmt: skip


def _num(value: int | float | None) -> float:
    return float("inf") if value is None else float(value)


def value_text(kind: ParamType, value: Value) -> str:
    """A value as text for ``setConfig`` (bools as ``true``/``false``, doubles as ``%g``)."""
    if kind is ParamType.BOOL:
        return "true" if value else "false"
    if kind is ParamType.DOUBLE and isinstance(value, (int, float)):
        return "%.10g" % float(value)  # noqa: UP031 -- C printf form, as ARIA's parser reads it
    return "" if value is None else str(value)


@dataclass(frozen=True, slots=True)
class ConfigSectionPacket(Payload):
    """One packet of ``getConfigBySectionsV4``: a section (or part of one) and its parameters.

    The empty packet that ends the reply decodes as ``end=True``. Subclasses give the older
    versions, whose layouts lack fields (see the module's text).
    """

    DATA_NAME = "getConfigBySectionsV4"
    SIDE = Side.REPLY
    VERSION: ClassVar[int] = 4

    name: str = ""
    comment: str = ""
    params: tuple[ConfigParam, ...] = ()
    category: str = ""
    index: int = 1
    """V3+: the part number (a section too big for one packet is split into consecutive parts)."""
    end: bool = False

    def encode(self) -> bytes:
        if self.end:
            return b""
        w = FieldWriter().byte(ord("S")).string(self.name).string(self.comment)
        if self.VERSION >= 2:
            w.string(self.category)
        if self.VERSION >= 3:
            w.ubyte2(self.index)
        for p in self.params:
            w.byte(ord("P"))
            p.write(w, self.VERSION)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        if not data:
            return cls(end=True)
        r = FieldReader(data)
        if r.ubyte("section marker") != ord("S"):
            raise PayloadError("a config section packet must start with 'S'")
        name, comment = r.string("section name"), r.string("section comment")
        category = r.string("section category") if cls.VERSION >= 2 else ""
        index = r.ubyte2("section part") if cls.VERSION >= 3 else 1
        params: list[ConfigParam] = []
        while not r.at_end():
            marker = r.ubyte("parameter marker")
            if marker != ord("P"):
                raise PayloadError(f"section {name!r}: expected 'P' before a parameter, got {marker:#04x}")
            params.append(ConfigParam.read(r, cls.VERSION))
        return cls(name, comment, tuple(params), category, index)


@register
@dataclass(frozen=True, slots=True)
class ConfigSectionPacketV3(ConfigSectionPacket):
    DATA_NAME = "getConfigBySectionsV3"
    VERSION = 3


@register
@dataclass(frozen=True, slots=True)
class ConfigSectionPacketV2(ConfigSectionPacket):
    DATA_NAME = "getConfigBySectionsV2"
    VERSION = 2


@register
@dataclass(frozen=True, slots=True)
class ConfigSectionPacketV1(ConfigSectionPacket):
    DATA_NAME = "getConfigBySections"
    VERSION = 1


register(ConfigSectionPacket)


@dataclass(frozen=True, slots=True)
class ConfigRequest(Payload):
    """``getConfigBySections*`` args: the last priority the client can show and the last it may edit.

    Empty args (both None) ask as an old client: nothing above ADVANCED, nothing read-only.
    """

    DATA_NAME = "getConfigBySectionsV4"
    SIDE = Side.ARGS

    last_priority: int | None = Priority.FACTORY
    last_editable: int | None = Priority.FACTORY

    def encode(self) -> bytes:
        w = FieldWriter()
        if self.last_priority is not None:
            w.byte(self.last_priority)
            if self.last_editable is not None:
                w.byte(self.last_editable)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        last = r.byte("last priority", None)
        editable = r.byte("last editable priority", None) if last is not None else None
        return cls(last, editable)


register(ConfigRequest)


@register
@dataclass(frozen=True, slots=True)
class SetConfig(Payload):
    """``setConfig`` args: ``(name, value)`` pairs; a ``("Section", name)`` pair starts a section."""

    DATA_NAME = "setConfig"
    SIDE = Side.ARGS

    pairs: tuple[tuple[str, str], ...] = ()

    @classmethod
    def of(cls, changes: dict[str, dict[str, str]]) -> SetConfig:
        """From ``{section: {parameter: value text}}``, each section introduced by its pair."""
        pairs: list[tuple[str, str]] = []
        for section, values in changes.items():
            pairs.append((SECTION_TAG, section))
            pairs += list(values.items())
        return cls(tuple(pairs))

    def encode(self) -> bytes:
        w = FieldWriter()
        for name, value in self.pairs:
            w.string(name).string(value)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        pairs: list[tuple[str, str]] = []
        while not r.at_end():
            name = r.string("parameter name")
            pairs.append((name, r.string(f"{name} value")))
        return cls(tuple(pairs))

    def by_section(self) -> list[tuple[str, str, str]]:
        """``(section, name, value)`` for every pair that is not a section pair."""
        out: list[tuple[str, str, str]] = []
        section = ""
        for name, value in self.pairs:
            if name.lower() == SECTION_TAG.lower():
                section = value
            else:
                out.append((section, name, value))
        return out


@register
@dataclass(frozen=True, slots=True)
class SetConfigReply(Payload):
    """``setConfig`` reply: empty when every value was taken, else the first error (naming the parameter)."""

    DATA_NAME = "setConfig"
    SIDE = Side.REPLY

    error: str = ""

    @property
    def accepted(self) -> bool:
        return not self.error

    def encode(self) -> bytes:
        return FieldWriter().string(self.error).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(FieldReader(data).string("setConfig answer", ""))


@register
@dataclass(frozen=True, slots=True)
class ConfigUpdated(EmptyPayload):
    """``configUpdated`` broadcast: another client (or a reload) changed the configuration."""

    DATA_NAME = "configUpdated"
    SIDE = Side.REPLY


@register
@dataclass(frozen=True, slots=True)
class ConfigSectionFlags(Payload):
    """``getConfigSectionFlags`` reply: each section's flags (``|``-separated words)."""

    DATA_NAME = "getConfigSectionFlags"
    SIDE = Side.REPLY

    sections: tuple[tuple[str, str], ...] = ()

    def encode(self) -> bytes:
        w = FieldWriter().byte4(len(self.sections))
        for name, flags in self.sections:
            w.string(name).string(flags)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        count = checked_count(r.byte4("section count"), 2, r, "section flags")
        return cls(tuple((r.string("section name"), r.string("section flags")) for _ in range(count)))


@register
@dataclass(frozen=True, slots=True)
class LastEditablePriority(Payload):
    """``getLastEditablePriority`` reply: parameters above this priority are shown but not editable."""

    DATA_NAME = "getLastEditablePriority"
    SIDE = Side.REPLY

    priority: int = Priority.EXPERT

    def encode(self) -> bytes:
        return FieldWriter().byte(self.priority).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(FieldReader(data).byte("last editable priority"))


@register
@dataclass(frozen=True, slots=True)
class ConfigCausingRestart(Payload):
    """``configCausingRestart`` broadcast: 1 = the server software restarts in a second, 2 = the robot."""

    DATA_NAME = "configCausingRestart"
    SIDE = Side.REPLY

    level: int = 1

    def encode(self) -> bytes:
        return FieldWriter().byte(self.level).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(FieldReader(data).byte("restart kind"))


__all__ = [
    "ConfigCausingRestart",
    "ConfigParam",
    "ConfigRequest",
    "ConfigSectionFlags",
    "ConfigSectionPacket",
    "ConfigUpdated",
    "LastEditablePriority",
    "ParamType",
    "Priority",
    "Restart",
    "SetConfig",
    "SetConfigReply",
]

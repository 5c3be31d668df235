"""Server information strings (protocol §4.11): labels once, values on every poll.

``getStrings`` carries no count and no labels: its values pair with the labels
of ``getStringsInfo`` by position. A WLAN signal, if a server publishes one at
all, is one of these items.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Self

from ..fields import FieldReader, FieldWriter
from .base import Payload, Side, checked_count, read_strings_to_end, register


@dataclass(frozen=True, slots=True)
class StringItem:
    label: str
    max_width: int
    """Suggested display width in characters."""


@register
@dataclass(frozen=True, slots=True)
class StringsInfo(Payload):
    """``getStringsInfo`` reply/broadcast: ``ubyte2`` count, then (label, ``ubyte2`` width) items."""

    DATA_NAME = "getStringsInfo"
    SIDE = Side.REPLY

    items: tuple[StringItem, ...] = ()

    @property
    def labels(self) -> tuple[str, ...]:
        return tuple(i.label for i in self.items)

    def pair(self, values: Strings) -> list[tuple[str, str]]:
        """(label, value) in order; items without a value (or values without a label) are left out."""
        return list(zip(self.labels, values.values, strict=False))

    def encode(self) -> bytes:
        w = FieldWriter().ubyte2(len(self.items))
        for item in self.items:
            w.string(item.label).ubyte2(item.max_width)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        count = checked_count(r.ubyte2("item count"), 3, r, "item count")
        return cls(tuple(StringItem(r.string("label"), r.ubyte2("max width")) for _ in range(count)))


@register
@dataclass(frozen=True, slots=True)
class Strings(Payload):
    """``getStrings`` reply: pre-formatted values in ``getStringsInfo`` order, no count."""

    DATA_NAME = "getStrings"
    SIDE = Side.REPLY

    values: tuple[str, ...] = ()

    def encode(self) -> bytes:
        w = FieldWriter()
        for v in self.values:
            w.string(v)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(read_strings_to_end(FieldReader(data), "value"))

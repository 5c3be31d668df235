"""Typed writers and readers for ARIA's packet fields (protocol §1.5–1.6).

Integers are little-endian. Strings are NUL-terminated 8-bit text with no
declared encoding: we decode them as latin-1, which maps every byte to one
character and therefore never fails and never loses a byte; we encode with
latin-1 too, replacing characters outside it with ``?`` (ARIA content is ASCII
in practice). Doubles travel as text in C's ``%g`` form, with ``INF``/``-INF``.

Reading past the end raises :class:`~rtmu.protocol.errors.FieldUnderrun`
naming the field, unless the caller passes a ``default`` (ARIA's own
behaviour for optional trailing arguments).
"""

from __future__ import annotations

import math
import re
import struct
from typing import Final, TypeVar

from .errors import FieldUnderrun

TEXT_ENCODING: Final = "latin-1"
MAX_DOUBLE_TEXT: Final = 255
"""ARIA reads at most 255 characters of a double's text."""

_T = TypeVar("_T")
_MISSING: Final = object()

_INT_FORMATS: Final = {
    "byte": struct.Struct("<b"),
    "ubyte": struct.Struct("<B"),
    "byte2": struct.Struct("<h"),
    "ubyte2": struct.Struct("<H"),
    "byte4": struct.Struct("<i"),
    "ubyte4": struct.Struct("<I"),
    "byte8": struct.Struct("<q"),
    "ubyte8": struct.Struct("<Q"),
}


def format_double(value: float) -> str:
    """The text ARIA's ``doubleToBuf`` writes for ``value`` (``%g``; ``INF``/``-INF``)."""
    if math.isinf(value):
        return "INF" if value > 0 else "-INF"
    if math.isnan(value):
        raise ValueError("NaN cannot be sent: ARIA peers read it inconsistently")
    return "%g" % value  # noqa: UP031 -- C printf semantics, on purpose


# What C's strtod accepts in the "C" locale, as one whole string: leading C whitespace, a sign, then
# decimal, hexadecimal, inf/infinity or nan(...). Python's float() is laxer (trailing and Unicode
# whitespace, underscores), so it only converts text that matched this first.
_STRTOD_TEXT: Final = re.compile(
    r"""[ \t\n\v\f\r]*[+-]?(?:
        (?P<hex>0x(?:[0-9a-f]+(?:\.[0-9a-f]*)?|\.[0-9a-f]+)(?:p[+-]?[0-9]+)?)
        | (?P<nan>nan(?:\([0-9a-z_]*\))?)
        | inf(?:inity)?
        | (?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:e[+-]?[0-9]+)?
    )""",
    re.IGNORECASE | re.VERBOSE | re.ASCII,
)


def parse_double(text: str) -> float:
    """Read a double as ARIA's ``bufToDouble`` does.

    Exactly ``INF``/``-INF`` are the infinities; otherwise the text must be one whole number as
    C's ``strtod`` reads it (``"12abc"``, ``""`` and ``"5 "`` are not), else the value is 0.0.
    """
    if text == "INF":
        return math.inf
    if text == "-INF":
        return -math.inf
    match = _STRTOD_TEXT.fullmatch(text)
    if match is None:
        return 0.0
    number = text.lstrip(" \t\n\v\f\r")
    if match["hex"] is not None:
        try:
            return float.fromhex(number)
        except OverflowError:  # strtod saturates to HUGE_VAL
            return -math.inf if number.startswith("-") else math.inf
    if match["nan"] is not None:
        return -math.nan if number.startswith("-") else math.nan
    return float(number)


def encode_text(text: str) -> bytes:
    return text.encode(TEXT_ENCODING, errors="replace")


class FieldWriter:
    """Builds a payload field by field; :meth:`bytes` returns it."""

    __slots__ = ("_parts",)

    def __init__(self) -> None:
        self._parts: list[bytes] = []

    def _int(self, kind: str, value: int) -> FieldWriter:
        try:
            self._parts.append(_INT_FORMATS[kind].pack(value))
        except struct.error as exc:
            raise ValueError(f"{value} does not fit in an ARIA {kind}") from exc
        return self

    def byte(self, value: int) -> FieldWriter:
        return self._int("byte", value)

    def ubyte(self, value: int) -> FieldWriter:
        return self._int("ubyte", value)

    def byte2(self, value: int) -> FieldWriter:
        return self._int("byte2", value)

    def ubyte2(self, value: int) -> FieldWriter:
        return self._int("ubyte2", value)

    def byte4(self, value: int) -> FieldWriter:
        return self._int("byte4", value)

    def ubyte4(self, value: int) -> FieldWriter:
        return self._int("ubyte4", value)

    def byte8(self, value: int) -> FieldWriter:
        return self._int("byte8", value)

    def ubyte8(self, value: int) -> FieldWriter:
        return self._int("ubyte8", value)

    def string(self, text: str | bytes) -> FieldWriter:
        """A NUL-terminated string; an embedded NUL would end it early, so it is refused."""
        raw = text if isinstance(text, bytes) else encode_text(text)
        if b"\x00" in raw:
            raise ValueError("an ARIA string cannot contain a NUL byte")
        self._parts.append(raw + b"\x00")
        return self

    def fixed_string(self, text: str | bytes, length: int) -> FieldWriter:
        """Exactly ``length`` bytes: truncated, or NUL-padded (``strToBufPadded``)."""
        raw = text if isinstance(text, bytes) else encode_text(text)
        self._parts.append(raw[:length].ljust(length, b"\x00"))
        return self

    def double(self, value: float) -> FieldWriter:
        return self.string(format_double(value))

    def raw(self, data: bytes | bytearray | memoryview) -> FieldWriter:
        """Bytes with no length; the reader must know how many from context."""
        self._parts.append(bytes(data))
        return self

    def __len__(self) -> int:
        return sum(len(p) for p in self._parts)

    def bytes(self) -> bytes:
        return b"".join(self._parts)


class FieldReader:
    """Reads fields from one payload in order; see the module notes on errors and text."""

    __slots__ = ("_data", "_pos")

    def __init__(self, data: bytes | bytearray | memoryview) -> None:
        self._data = bytes(data)
        self._pos = 0

    @property
    def position(self) -> int:
        return self._pos

    @property
    def remaining(self) -> int:
        return len(self._data) - self._pos

    def at_end(self) -> bool:
        return self._pos >= len(self._data)

    def _int(self, kind: str, field: str, default: object) -> int:
        fmt = _INT_FORMATS[kind]
        if self.remaining < fmt.size:
            if default is not _MISSING:
                self._pos = len(self._data)
                return default  # type: ignore[return-value]
            raise FieldUnderrun(field or kind, fmt.size, self.remaining)
        (value,) = fmt.unpack_from(self._data, self._pos)
        self._pos += fmt.size
        return value

    def byte(self, field: str = "", default: object = _MISSING) -> int:
        return self._int("byte", field, default)

    def ubyte(self, field: str = "", default: object = _MISSING) -> int:
        return self._int("ubyte", field, default)

    def byte2(self, field: str = "", default: object = _MISSING) -> int:
        return self._int("byte2", field, default)

    def ubyte2(self, field: str = "", default: object = _MISSING) -> int:
        return self._int("ubyte2", field, default)

    def byte4(self, field: str = "", default: object = _MISSING) -> int:
        return self._int("byte4", field, default)

    def ubyte4(self, field: str = "", default: object = _MISSING) -> int:
        return self._int("ubyte4", field, default)

    def byte8(self, field: str = "", default: object = _MISSING) -> int:
        return self._int("byte8", field, default)

    def ubyte8(self, field: str = "", default: object = _MISSING) -> int:
        return self._int("ubyte8", field, default)

    def string_bytes(self, field: str = "", default: object = _MISSING) -> bytes:
        """Raw bytes of a NUL-terminated string. An unterminated one runs to the payload end."""
        if self.at_end():
            if default is not _MISSING:
                return default  # type: ignore[return-value]
            raise FieldUnderrun(field or "string", 1, 0)
        end = self._data.find(b"\x00", self._pos)
        if end < 0:
            raw = self._data[self._pos :]
            self._pos = len(self._data)
            return raw
        raw = self._data[self._pos : end]
        self._pos = end + 1
        return raw

    def string(self, field: str = "", default: object = _MISSING) -> str:
        raw = self.string_bytes(field, default)
        return raw.decode(TEXT_ENCODING) if isinstance(raw, bytes) else raw  # a default comes back as given

    def fixed_string(self, length: int, field: str = "") -> str:
        raw = self.raw(length, field or "fixed string")
        return raw.split(b"\x00", 1)[0].decode(TEXT_ENCODING)

    def double(self, field: str = "", default: object = _MISSING) -> float:
        if self.at_end() and default is not _MISSING:
            return default  # type: ignore[return-value]
        return parse_double(self.string(field or "double")[:MAX_DOUBLE_TEXT])

    def raw(self, length: int, field: str = "") -> bytes:
        if length < 0 or self.remaining < length:
            raise FieldUnderrun(field or "raw bytes", length, self.remaining)
        raw = self._data[self._pos : self._pos + length]
        self._pos += length
        return raw

    def rest(self) -> bytes:
        """Everything not read yet (e.g. the JPEG after a picture's width and height)."""
        raw = self._data[self._pos :]
        self._pos = len(self._data)
        return raw

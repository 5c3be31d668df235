"""Field layouts read from a data's own argument and return descriptions, and typed arguments.

ArNetworking sends a description of each data's arguments and reply with the data list, in prose
that names ARIA's field types: ``"byte4: x (mm); byte4: y (mm); optional byte4: heading"``,
``"uByte2: width, uByte2: height"``, ``"<repeat> string: goal"``. That prose is the only layout a
console has for the hundreds of data RTMU does not know, so :func:`parse_layout` reads the typed
fields out of it (best effort: a description that names no types gives an empty, *unknown* layout
and the operator says the types instead). :func:`encode_arguments` turns the operator's words into
the request's bytes, type by type, refusing what a field cannot carry.

Server text is untrusted: only the first :data:`MAX_DESCRIPTION_SCAN` characters are read and at
most :data:`MAX_FIELDS` fields kept, so a hostile description costs a bounded scan.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from ..protocol.fields import FieldWriter, format_double
from ..protocol.packet import MAX_PAYLOAD

KINDS: tuple[str, ...] = ("byte", "ubyte", "byte2", "ubyte2", "byte4", "ubyte4", "double", "string")
"""The argument types an operator may name (``--type``): ARIA's integers, its doubles (sent as
text) and its NUL-terminated strings."""
READ_KINDS: tuple[str, ...] = (*KINDS, "byte8", "ubyte8")
"""What a reply layout may hold (ARIA's 64-bit integers are never arguments in practice)."""
INT_RANGES: dict[str, tuple[int, int]] = {
    "byte": (-(1 << 7), (1 << 7) - 1),
    "ubyte": (0, (1 << 8) - 1),
    "byte2": (-(1 << 15), (1 << 15) - 1),
    "ubyte2": (0, (1 << 16) - 1),
    "byte4": (-(1 << 31), (1 << 31) - 1),
    "ubyte4": (0, (1 << 32) - 1),
    "byte8": (-(1 << 63), (1 << 63) - 1),
    "ubyte8": (0, (1 << 64) - 1),
}
MAX_DESCRIPTION_SCAN = 4000
MAX_FIELDS = 64
MAX_LABEL = 80
NO_ARGUMENTS = frozenset({"", "none", "none.", "no arguments", "nothing"})

# A typed field: an optional "optional", ARIA's type word (any case, "u" for unsigned, "int" and
# "uint" as some servers write them), then a colon and the field's label up to ; , or a new field.
_KIND = r"\b(?:u?byte[248]?|u?int(?:8|16|32)?|double|string)\s*:"
_FIELD = re.compile(
    r"(?P<optional>\boptional\s+|\[\s*)?\b(?P<kind>u?byte[248]?|u?int(?:8|16|32)?|double|string)\s*:\s*"
    rf"(?P<label>(?:(?!{_KIND})(?:\([^()]*\)|[^;,:<(]))*)",
    re.IGNORECASE,
)
_REPEAT = re.compile(r"repeat|for each|\btimes\b|\bper (?:point|reading|entry|item|sensor)", re.IGNORECASE)
_NONE = re.compile(r"\s*none\b", re.IGNORECASE)
"""``none``, ``None``, ``none (sent by the server only)``: no fields."""
_COUNT_LABEL = re.compile(r"\b(num|count|number)", re.IGNORECASE)
_ALIASES = {
    "int": "byte4",
    "int32": "byte4",
    "uint": "ubyte4",
    "uint32": "ubyte4",
    "int16": "byte2",
    "uint16": "ubyte2",
    "int8": "byte",
    "uint8": "ubyte",
    "byte1": "byte",
    "ubyte1": "ubyte",
}


@dataclass(frozen=True, slots=True)
class FieldSpec:
    kind: str
    """One of :data:`READ_KINDS`."""
    label: str = ""
    optional: bool = False


@dataclass(frozen=True, slots=True)
class Layout:
    """The typed fields a description names, in order; ``repeat_from``: where a repeating group
    starts (None: the fields come once)."""

    fields: tuple[FieldSpec, ...] = ()
    repeat_from: int | None = None
    known: bool = True
    """False when the description says something but names no type RTMU can read."""

    @property
    def required(self) -> int:
        return sum(1 for f in self.fields if not f.optional)


def kind_of(word: str) -> str | None:
    """ARIA's type word (``uByte2``, ``int``, ``string`` …) as one of :data:`READ_KINDS`, or None."""
    w = word.strip().lower()
    w = _ALIASES.get(w, w)
    return w if w in READ_KINDS else None


def parse_layout(description: str) -> Layout:
    """The typed fields of an argument or return description (see the module notes)."""
    text = description[:MAX_DESCRIPTION_SCAN]
    if text.strip().lower() in NO_ARGUMENTS or _NONE.match(text):
        return Layout()
    fields: list[FieldSpec] = []
    repeat_at: int | None = None
    marker = _REPEAT.search(text)
    for match in _FIELD.finditer(text):
        if len(fields) >= MAX_FIELDS:
            break
        kind = kind_of(match["kind"])
        if kind is None:
            continue
        if marker is not None and repeat_at is None and match.start() > marker.start():
            repeat_at = len(fields)
        label = " ".join(match["label"].split()).rstrip(" ]")[:MAX_LABEL]
        # Optional fields trail: once one is, every later one is too (ARIA reads them with defaults).
        optional = bool(match["optional"]) or any(f.optional for f in fields)
        fields.append(FieldSpec(kind, label, optional))
    if not fields:
        return Layout(known=False)
    if marker is not None and repeat_at is None:
        # "string: route name, repeated" or "byte4: x, byte4: y per point": the group ends the list,
        # after its count where one is named.
        counts = [i for i, f in enumerate(fields) if _COUNT_LABEL.search(f.label)]
        repeat_at = counts[-1] + 1 if counts and counts[-1] + 1 < len(fields) else 0
    return Layout(tuple(fields), repeat_at)


class ArgumentError(ValueError):
    """The operator's arguments do not fit the data's layout (or a type); the message says how."""


def argument_kinds(layout: Layout, values: list[str], explicit: list[str] | None) -> list[str]:
    """The type of each value: ``explicit`` when given, else the layout's, else an error."""
    if explicit:
        if len(explicit) != len(values):
            raise ArgumentError(f"{len(explicit)} --type given for {len(values)} argument(s): give one each")
        kinds = []
        for word in explicit:
            kind = kind_of(word)
            if kind not in KINDS:
                raise ArgumentError(f"unknown --type {word!r} (types: {', '.join(KINDS)})")
            kinds.append(kind)
        return kinds
    if not values:
        if layout.required:
            raise ArgumentError(f"it takes {_count(layout.required)}: {describe(layout)}")
        return []
    if not layout.known or not layout.fields:
        raise ArgumentError(
            "its argument description names no field types RTMU can read: give --type for each "
            f"argument ({', '.join(KINDS)})"
        )
    fields = list(layout.fields)
    if layout.repeat_from is not None:  # a repeating group repeats for as many values as given
        group = fields[layout.repeat_from :] or fields
        while len(fields) < len(values):
            fields += group
    if len(values) > len(fields):
        raise ArgumentError(f"it takes at most {_count(len(fields))}: {describe(layout)}")
    if len(values) < layout.required:
        raise ArgumentError(f"it takes {_count(layout.required)}: {describe(layout)}")
    kinds = [f.kind for f in fields[: len(values)]]
    bad = [k for k in kinds if k not in KINDS]
    if bad:
        raise ArgumentError(f"RTMU does not send {bad[0]} arguments: give --type")
    return kinds


def encode_arguments(layout: Layout, values: list[str], explicit: list[str] | None = None) -> bytes:
    """The request payload for ``values`` (the operator's words), typed by ``explicit`` or the layout."""
    writer = FieldWriter()
    for index, (kind, text) in enumerate(zip(argument_kinds(layout, values, explicit), values, strict=True)):
        where = f"argument {index + 1} ({kind})"
        if kind == "string":
            try:
                text.encode("latin-1")
            except UnicodeEncodeError:
                raise ArgumentError(f"{where}: ARIA strings carry latin-1 characters only") from None
            writer.string(text)
        elif kind == "double":
            try:
                number = float(text)
            except ValueError:
                raise ArgumentError(f"{where}: {text!r} is not a number") from None
            if math.isnan(number):
                raise ArgumentError(f"{where}: NaN cannot be sent")
            format_double(number)
            writer.double(number)
        else:
            try:
                number = int(text, 0)
            except ValueError:
                raise ArgumentError(f"{where}: {text!r} is not a whole number") from None
            low, high = INT_RANGES[kind]
            if not low <= number <= high:
                raise ArgumentError(f"{where}: {number} is outside {low}…{high}")
            getattr(writer, kind)(number)
    if len(writer) > MAX_PAYLOAD:
        raise ArgumentError(
            f"the arguments take {len(writer)} bytes; one packet carries at most {MAX_PAYLOAD}"
        )
    return writer.bytes()


def describe(layout: Layout) -> str:
    """The layout in a line: ``byte4 x (mm), byte4 y (mm), [byte4 heading]``."""
    if not layout.fields:
        return "no arguments" if layout.known else "types not known"
    parts = []
    for i, f in enumerate(layout.fields):
        text = f"{f.kind} {f.label}".strip()
        parts.append(f"[{text}]" if f.optional else text)
        if layout.repeat_from is not None and i + 1 == len(layout.fields):
            parts.append("…")
    return ", ".join(parts)


def _count(n: int) -> str:
    return f"{n} argument{'s' if n != 1 else ''}"

"""A reply packet seen three ways — bytes, a best-effort field split, RTMU's own payload type.

For data RTMU does not know, the bytes are all there is; ARIA's fields are not self-describing,
so :func:`split_fields` reads them first as the data's return description names them
(:mod:`rtmu.client.console_layout`), then guesses the rest: a run of text ending in NUL is a
string (a number written as text is one of ARIA's doubles), anything else a little-endian
integer of 4, 2 or 1 bytes. Where RTMU has a payload type for the data, :func:`view_packet` also
decodes it and shows its fields (or why it did not decode).

Everything is bounded for hostile replies: at most :data:`MAX_FIELDS_SHOWN` fields are made per
packet (the rest are only counted, at C speed per field), :data:`MAX_HEX_BYTES` bytes are shown
as hex, and the typed view's lists and texts are cut (:func:`bounded`).
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass
from typing import Any

from ..protocol.errors import ProtocolError
from ..protocol.fields import TEXT_ENCODING, FieldReader, parse_double
from ..protocol.payloads import Side, payload_type_for
from .console_layout import Layout

MAX_FIELDS_SHOWN = 200
MAX_HEX_BYTES = 512
MAX_TEXT = 2000
MAX_LIST = 50
_TEXT_RUN = re.compile(rb"[\x20-\x7e\t\r\n\xa0-\xff]+\x00")
"""A string as ARIA writes one: printable 8-bit text, then NUL."""
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|[+-]?INF")
_WIDTHS = {"byte": 1, "ubyte": 1, "byte2": 2, "ubyte2": 2, "byte4": 4, "ubyte4": 4, "byte8": 8, "ubyte8": 8}


@dataclass(frozen=True, slots=True)
class Field:
    kind: str
    """``string``, ``double`` (ARIA sends doubles as text), ``byte``…``ubyte8``."""
    value: int | float | str
    offset: int
    size: int
    label: str = ""
    """The return description's name for it; empty where the field was guessed."""

    def to_json(self) -> dict[str, Any]:
        value = self.value
        if isinstance(value, float) and not math.isfinite(value):
            value = str(value)
        out: dict[str, Any] = {"kind": self.kind, "value": value, "offset": self.offset}
        if self.label:
            out["label"] = self.label
        return out


@dataclass(frozen=True, slots=True)
class PacketView:
    size: int
    hex: str
    """The first :data:`MAX_HEX_BYTES` bytes as hex pairs."""
    fields: tuple[Field, ...]
    more_fields: int
    """Fields past :data:`MAX_FIELDS_SHOWN`: counted, not made."""
    typed_name: str = ""
    """RTMU's payload type for this data ("" where it has none)."""
    typed: Any = None
    """That type's fields, bounded (None where there is no type or it did not decode)."""
    typed_error: str = ""

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "size": self.size,
            "hex": self.hex,
            "fields": [f.to_json() for f in self.fields],
            "more_fields": self.more_fields,
        }
        if self.typed_name:
            out["typed"] = {"type": self.typed_name, "fields": self.typed, "error": self.typed_error or None}
        return out


def hex_of(payload: bytes) -> str:
    shown = payload[:MAX_HEX_BYTES].hex(" ")
    return shown + (f" … (+{len(payload) - MAX_HEX_BYTES} bytes)" if len(payload) > MAX_HEX_BYTES else "")


def split_fields(payload: bytes, layout: Layout | None = None) -> tuple[tuple[Field, ...], int]:
    """The payload as fields — the described ones, then guesses — and how many more were not made."""
    fields: list[Field] = []
    more = 0
    pos = 0
    if layout is not None and layout.fields:
        pos = _described(payload, layout, fields)
    while pos < len(payload):
        if len(fields) >= MAX_FIELDS_SHOWN:
            more += _count_guesses(payload, pos)
            break
        field = _guess(payload, pos)
        fields.append(field)
        pos += field.size
    return tuple(fields), more


def _described(payload: bytes, layout: Layout, out: list[Field]) -> int:
    """Read the layout's fields (its repeating group again while bytes remain); where it stopped."""
    reader = FieldReader(payload)
    specs = list(layout.fields)
    group = specs[layout.repeat_from :] if layout.repeat_from is not None else []
    index = 0
    while len(out) < MAX_FIELDS_SHOWN and not reader.at_end():
        if index >= len(specs):
            if not group:
                break
            specs += group
        spec = specs[index]
        index += 1
        start = reader.position
        try:
            if spec.kind in ("string", "double"):
                text = reader.string(spec.label)
                value: int | float | str = text
                if spec.kind == "double":
                    value = parse_double(text[:255]) if _NUMBER.fullmatch(text) else text
                kind = "double" if isinstance(value, float) else "string"
            else:
                value, kind = getattr(reader, spec.kind)(spec.label), spec.kind
        except ProtocolError:
            return start  # the bytes end inside this field: guess the rest
        out.append(Field(kind, _cut(value), start, reader.position - start, spec.label))
    return reader.position


def _guess(payload: bytes, pos: int) -> Field:
    run = _TEXT_RUN.match(payload, pos)
    if run is not None:
        text = payload[pos : run.end() - 1].decode(TEXT_ENCODING)
        if _NUMBER.fullmatch(text):
            return Field("double", parse_double(text), pos, run.end() - pos)
        return Field("string", _cut(text), pos, run.end() - pos)
    left = len(payload) - pos
    kind = "byte4" if left >= 4 else "byte2" if left >= 2 else "ubyte"
    size = _WIDTHS[kind]
    return Field(kind, int.from_bytes(payload[pos : pos + size], "little", signed=kind != "ubyte"), pos, size)


def _count_guesses(payload: bytes, pos: int) -> int:
    """How many fields :func:`_guess` would make from ``pos`` on, without making them."""
    count = 0
    end = len(payload)
    while pos < end:
        run = _TEXT_RUN.match(payload, pos)
        left = end - pos
        pos = run.end() if run is not None else pos + (4 if left >= 4 else 2 if left >= 2 else 1)
        count += 1
    return count


def view_packet(name: str, payload: bytes, layout: Layout | None = None) -> PacketView:
    """One packet of data ``name`` in every view RTMU has for it."""
    fields, more = split_fields(payload, layout)
    typed_name, typed, error = "", None, ""
    cls = payload_type_for(name, Side.REPLY)
    if cls is not None:
        typed_name = cls.__name__
        try:
            typed = bounded(cls.decode(payload).to_fields())
        except ProtocolError as exc:
            error = f"does not decode as {typed_name}: {exc}"
        except (ValueError, OverflowError) as exc:  # a value a type refuses (an enum out of range…)
            error = f"does not decode as {typed_name}: {exc}"
    return PacketView(len(payload), hex_of(payload), fields, more, typed_name, typed, error)


def bounded(value: Any) -> Any:
    """JSON-able ``value`` with lists past :data:`MAX_LIST` items and texts past :data:`MAX_TEXT` cut."""
    if isinstance(value, dict):
        return {str(k): bounded(v) for k, v in list(value.items())[:MAX_LIST]}
    if isinstance(value, (list, tuple)):
        items = [bounded(v) for v in value[:MAX_LIST]]
        if len(value) > MAX_LIST:
            items.append(f"… (+{len(value) - MAX_LIST} more)")
        return items
    if isinstance(value, str):
        return _cut(value)
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return bounded(dataclasses.asdict(value))
    return value


def _cut(value: Any) -> Any:
    if isinstance(value, str) and len(value) > MAX_TEXT:
        return value[: MAX_TEXT - 1] + "…"
    return value

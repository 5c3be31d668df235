"""The shape every typed payload shares, and the registry that finds one by data name.

A payload type is a frozen dataclass with ONE ``encode`` and ONE ``decode``,
used by the client and the simulator alike. Requests and replies of the same
data often differ (``getSensorCurrent`` asks with names and answers with
readings), so each type says which side it is: ``ARGS`` (what a client sends
in a request) or ``REPLY`` (what a server sends back or broadcasts).

Some data names are families rather than names: camera data carry the camera's
name as a suffix (``getPictureCam1``) and range devices publish
``<device>Current``. A type says so with :attr:`Payload.NAME_MATCH`, and
:func:`payload_type_for` finds it for any member of the family.

Decoders raise only :class:`~rtmu.protocol.errors.ProtocolError` subclasses
(``FieldUnderrun`` naming the field, ``PayloadError`` for bad counts/values);
bytes after the last field are ignored, as ARIA does, unless a type keeps them
(forwarded video) so that ``encode(decode(b)) == b`` holds for wire payloads.
"""

from __future__ import annotations

import dataclasses
import importlib
import struct
from collections.abc import Callable
from enum import Enum
from typing import Any, ClassVar, Final, Self, TypeVar

from ..errors import PayloadError
from ..fields import FieldReader, FieldWriter


class Side(Enum):
    ARGS = "args"
    REPLY = "reply"

    # Every packet's type lookup hashes a (name, side) key; Enum's own __hash__ is a Python call
    # (hash of the member's name), a third of a status packet's decode. Members are singletons and
    # compare by identity, so the identity hash is the same contract in C.
    __hash__ = object.__hash__


class NameMatch(Enum):
    """How a type's ``DATA_NAME`` relates to the data names it decodes."""

    EXACT = "exact"
    PREFIX = "prefix"
    """``DATA_NAME`` + anything, e.g. ``getPicture`` → ``getPictureCam1`` (camera suffix)."""
    SUFFIX = "suffix"
    """anything + ``DATA_NAME``, e.g. ``Current`` → ``sonarCurrent`` (range devices)."""


class Payload:
    """Base of typed payloads; subclasses are frozen, slotted dataclasses."""

    __slots__ = ()

    DATA_NAME: ClassVar[str]
    SIDE: ClassVar[Side]
    NAME_MATCH: ClassVar[NameMatch] = NameMatch.EXACT

    def encode(self) -> bytes:
        raise NotImplementedError

    @classmethod
    def decode(cls, data: bytes) -> Self:
        raise NotImplementedError

    def to_fields(self) -> dict[str, Any]:
        """Plain JSON-able fields, for ``rtmu decode`` and ``--json`` output."""
        out: dict[str, Any] = {}
        for f in dataclasses.fields(self):  # type: ignore[arg-type]
            out[f.name] = _jsonable(getattr(self, f.name))
        return out


class EmptyPayload(Payload):
    """A payload with no fields: the data's name is the whole message (``mapUpdated``, heartbeats)."""

    __slots__ = ()

    def encode(self) -> bytes:
        return b""

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls()


class SingleField(Payload):
    """A payload of exactly one field, carried by one :class:`FieldWriter`/:class:`FieldReader` kind.

    Subclasses are dataclasses with a single field and name its wire kind, so
    the many one-number and one-string payloads share one codec.
    """

    __slots__ = ()

    FIELD_KIND: ClassVar[str]
    """The writer/reader method that carries the field: ``"double"``, ``"string"``, ``"ubyte4"``…"""
    FIELD_LABEL: ClassVar[str]
    """The field's name in a decode error."""

    def encode(self) -> bytes:
        (field,) = dataclasses.fields(self)  # type: ignore[arg-type]
        return getattr(FieldWriter(), self.FIELD_KIND)(getattr(self, field.name)).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(getattr(FieldReader(data), cls.FIELD_KIND)(cls.FIELD_LABEL))  # type: ignore[call-arg]


class SingleFlag(SingleField):
    """A :class:`SingleField` holding a bool: sent as 1 or 0, and any non-zero value reads as True."""

    __slots__ = ()

    def encode(self) -> bytes:
        (field,) = dataclasses.fields(self)  # type: ignore[arg-type]
        return getattr(FieldWriter(), self.FIELD_KIND)(1 if getattr(self, field.name) else 0).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(getattr(FieldReader(data), cls.FIELD_KIND)(cls.FIELD_LABEL) != 0)  # type: ignore[call-arg]


def _jsonable(value: Any) -> Any:
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _jsonable(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, bytes):
        return {"bytes": len(value)} if len(value) > 64 else value.hex()
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, float) and value != value:  # NaN
        return None
    if hasattr(value, "tolist"):  # numpy arrays
        return value.tolist()
    return value


_REGISTRY: dict[tuple[str, Side], type[Payload]] = {}
_LOOKUP_CACHE: dict[tuple[str, Side], type[Payload] | None] = {}
_MODULE_OF: dict[str, tuple[str, ...]] = {}
"""Data name → the payload modules defining it (from :mod:`.names`), filled on first use."""
P = TypeVar("P", bound=type[Payload])


def register(cls: P) -> P:
    """Class decorator: make ``cls`` the payload type for its data name and side."""
    key = (cls.DATA_NAME, cls.SIDE)
    if key in _REGISTRY:
        raise RuntimeError(f"two payload types for {key}")
    _REGISTRY[key] = cls
    _LOOKUP_CACHE.clear()
    _DECODERS.clear()
    return cls


def _load_for(data_name: str) -> None:
    """Import the payload modules that may hold a type for ``data_name``: the one that registers it
    exactly and those of every family name it starts or ends with (each imported once)."""
    if not _MODULE_OF:
        from .names import MODULE_NAMES

        index: dict[str, tuple[str, ...]] = {}
        for module, names in MODULE_NAMES.items():
            for name in names:
                index[name] = (*index.get(name, ()), module)
        _MODULE_OF.update(index)
    wanted = {
        module
        for name, modules in _MODULE_OF.items()
        if data_name.startswith(name) or data_name.endswith(name)
        for module in modules
    }
    for module in sorted(wanted):
        importlib.import_module(f"{__package__}.{module}")


def load_all() -> None:
    """Import every payload module (every type registered): for :func:`registered` and tools that
    list or search all types."""
    from .names import PAYLOAD_MODULES

    for module in PAYLOAD_MODULES:
        importlib.import_module(f"{__package__}.{module}")


def payload_type(data_name: str, side: Side) -> type[Payload] | None:
    """The payload type registered under exactly this data name, or None."""
    found = _REGISTRY.get((data_name, side))
    if found is None:
        _load_for(data_name)
        found = _REGISTRY.get((data_name, side))
    return found


def payload_type_for(data_name: str, side: Side) -> type[Payload] | None:
    """The payload type for a data name as a server lists it, or None when we have no decoder.

    An exact registration wins; otherwise the longest ``PREFIX`` type the name
    starts with (camera data: ``getPictureCam1``), then the longest ``SUFFIX``
    type it ends with (range devices: ``sonarCurrent``).
    """
    key = (data_name, side)
    try:
        return _LOOKUP_CACHE[key]
    except KeyError:
        pass
    exact = _REGISTRY.get(key)
    if exact is None:
        _load_for(data_name)  # its modules, before the first answer is cached
    found = exact or _lookup(data_name, side)
    if len(_LOOKUP_CACHE) < 4096:  # names come from the server: keep the cache bounded
        _LOOKUP_CACHE[key] = found
    return found


def _lookup(data_name: str, side: Side) -> type[Payload] | None:
    exact = _REGISTRY.get((data_name, side))
    if exact is not None:
        return exact
    best: type[Payload] | None = None
    for match, fits in (
        (NameMatch.PREFIX, data_name.startswith),
        (NameMatch.SUFFIX, data_name.endswith),
    ):
        for (name, s), cls in _REGISTRY.items():
            fitting = s is side and cls.NAME_MATCH is match and fits(name) and len(name) < len(data_name)
            if fitting and (best is None or len(name) > len(best.DATA_NAME)):
                best = cls
        if best is not None:
            return best
    return None


def decode_payload(data_name: str, side: Side, data: bytes) -> Payload | None:
    """Decode ``data`` with the type for ``data_name`` (see :func:`payload_type_for`); None if unknown."""
    decode = _decoder_for((data_name, side), _UNCACHED)  # every packet: one lookup, no method binding
    if decode is _UNCACHED:
        cls = payload_type_for(data_name, side)
        decode = None if cls is None else cls.decode
        if len(_DECODERS) < 4096:  # names come from the server: keep the cache bounded
            _DECODERS[(data_name, side)] = decode
    return None if decode is None else decode(data)


_UNCACHED: Final[Any] = object()
_DECODERS: dict[tuple[str, Side], Callable[[bytes], Payload] | None] = {}
"""(data name, side) → the bound ``decode`` of its type (None: no type), as :data:`_LOOKUP_CACHE`."""
_decoder_for = _DECODERS.get


def registered() -> dict[tuple[str, Side], type[Payload]]:
    """Every payload type, by (data name, side); imports every payload module first."""
    load_all()
    return dict(_REGISTRY)


# -- small helpers the payload modules share ------------------------------------


def checked_count(count: int, item_size: int, reader: FieldReader, field: str) -> int:
    """Refuse a count that cannot fit in the bytes left, before anything is allocated.

    ``item_size`` is the smallest number of bytes one item can take (1 for a string).
    """
    if count < 0:
        raise PayloadError(f"{field} is negative ({count})")
    if count * item_size > reader.remaining:
        raise PayloadError(
            f"{field} claims {count} items of at least {item_size} bytes, only {reader.remaining} bytes left"
        )
    return count


XY = struct.Struct("<ii")
"""One ``byte4`` x, ``byte4`` y pair in mm: how range readings and drawings carry their points."""


def read_xy(reader: FieldReader, count: int, field: str) -> tuple[tuple[int, int], ...]:
    """``count`` x/y pairs, the count refused (named ``field``) before anything is allocated."""
    checked_count(count, XY.size, reader, field)
    return tuple(XY.iter_unpack(reader.raw(count * XY.size, field)))


def write_xy(writer: FieldWriter, points: tuple[tuple[int, int], ...], what: str) -> None:
    """The pairs after their count; ``what`` names one in the error when a value does not fit."""
    try:
        writer.raw(b"".join(XY.pack(x, y) for x, y in points))
    except struct.error as exc:
        raise ValueError(f"a {what} does not fit in byte4 x/y: {exc}") from exc


def read_strings_to_end(reader: FieldReader, field: str) -> tuple[str, ...]:
    """Strings until the payload ends: lists that carry no count (``getGoals``, ``getStrings``)."""
    out: list[str] = []
    while not reader.at_end():
        out.append(reader.string(field))
    return tuple(out)

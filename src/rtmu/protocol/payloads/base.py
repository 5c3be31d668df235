"""The shape every typed payload shares, and the registry that finds one by data name.

A payload type is a frozen dataclass with ONE ``encode`` and ONE ``decode``,
used by the client and the simulator alike. Requests and replies of the same
data often differ (``getSensorCurrent`` asks with names and answers with
readings), so each type says which side it is: ``ARGS`` (what a client sends
in a request) or ``REPLY`` (what a server sends back or broadcasts).
"""

from __future__ import annotations

import dataclasses
from enum import Enum
from typing import Any, ClassVar, Self, TypeVar


class Side(Enum):
    ARGS = "args"
    REPLY = "reply"


class Payload:
    """Base of typed payloads; subclasses are frozen dataclasses."""

    DATA_NAME: ClassVar[str]
    SIDE: ClassVar[Side]

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
P = TypeVar("P", bound=type[Payload])


def register(cls: P) -> P:
    """Class decorator: make ``cls`` the payload type for its data name and side."""
    key = (cls.DATA_NAME, cls.SIDE)
    if key in _REGISTRY:
        raise RuntimeError(f"two payload types for {key}")
    _REGISTRY[key] = cls
    return cls


def payload_type(data_name: str, side: Side) -> type[Payload] | None:
    """The payload type for a data name, or None when we have no decoder for it."""
    return _REGISTRY.get((data_name, side))


def registered() -> dict[tuple[str, Side], type[Payload]]:
    return dict(_REGISTRY)

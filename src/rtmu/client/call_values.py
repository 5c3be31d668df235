"""What crosses :class:`~rtmu.client.connection.AriaClient`'s calls: request arguments on the way out
(:func:`encode_args`, :func:`request_parts`), :class:`Reply` and :class:`Packet` on the way back.

A typed :class:`~rtmu.protocol.payloads.Payload` names its own data and encodes itself; the other
argument kinds are encoded the way ARIA's clients send them. Decoding a reply or a packet to its typed
payload fails with the client's own errors (:class:`~rtmu.client.errors.MalformedReply`,
:class:`~rtmu.client.errors.NotSupported`), never the codec's.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from ..protocol.client_connection import named
from ..protocol.errors import ProtocolError
from ..protocol.fields import FieldWriter
from ..protocol.payloads import Payload, Side, decode_payload
from .errors import MalformedReply, NotSupported

Arg = Payload | bytes | bytearray | str | float | int | bool


def encode_args(args: tuple[Arg, ...]) -> bytes:
    """Request arguments → payload bytes.

    A typed :class:`Payload` encodes itself; ``bytes`` go as they are; ``str`` is an
    ARIA string; ``bool`` a ubyte 0/1; other numbers an ARIA double (as text).
    Integer fields of other sizes: pass bytes built with ``FieldWriter`` or a typed payload.
    """
    w = FieldWriter()
    for arg in args:
        if isinstance(arg, Payload):
            w.raw(arg.encode())
        elif isinstance(arg, (bytes, bytearray)):
            w.raw(arg)
        elif isinstance(arg, str):
            w.string(arg)
        elif isinstance(arg, bool):
            w.ubyte(1 if arg else 0)
        elif isinstance(arg, (int, float)):
            w.double(float(arg))
        else:
            raise TypeError(f"cannot encode request argument {arg!r}")
    return w.bytes()


def request_parts(what: str | Payload, args: tuple[Arg, ...]) -> tuple[str, bytes]:
    """(data name, argument bytes) from a call's arguments; a typed payload names its own data."""
    if isinstance(what, Payload):
        if args:
            raise TypeError("a typed payload carries its own arguments")
        try:
            return named(what)
        except ProtocolError as exc:
            raise TypeError(str(exc)) from None
    return what, encode_args(args)


@dataclass(frozen=True, slots=True)
class Reply:
    """The packet(s) answering one request: ``payloads`` in arrival order (one for most data)."""

    name: str
    payloads: tuple[bytes, ...]
    received_at: float = field(compare=False)

    @property
    def payload(self) -> bytes:
        """The first (usually only) payload; ``b""`` if there was none."""
        return self.payloads[0] if self.payloads else b""

    def decode(self) -> Payload:
        """The first payload as its typed reply class; :class:`MalformedReply` if it does not decode."""
        return _decode_typed(self.name, self.payload, "replies")


@dataclass(frozen=True, slots=True)
class Packet:
    """One reply or broadcast packet handed to a subscription handler."""

    name: str
    payload: bytes
    received_at: float

    def decode(self) -> Payload:
        return _decode_typed(self.name, self.payload, "packets")


def _decode_typed(name: str, payload: bytes, what: str) -> Payload:
    try:
        typed = decode_payload(name, Side.REPLY, payload)
    except ProtocolError as exc:
        raise MalformedReply(f"the server sent a malformed {name!r} packet: {exc}") from None
    if typed is None:
        raise NotSupported(name, f"RTMU has no decoder for {name!r} {what}")
    return typed


Handler = Callable[[Packet], None]
"""A subscription's handler: called on the network loop with each packet of its data (must be quick)."""

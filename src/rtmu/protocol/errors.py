"""The protocol layer's exceptions: one family, so callers can catch network faults in one place."""

from __future__ import annotations


class ProtocolError(Exception):
    """Something a peer sent (or we were asked to send) breaks the ArNetworking protocol."""


class PacketTooLong(ProtocolError):
    """A packet would exceed ARIA's 32000-byte limit; ARIA's sender would silently drop it."""


class FieldUnderrun(ProtocolError):
    """A field was read past the end of a payload.

    ARIA reads a missing field as 0 or "" and carries on; we make that explicit
    so a short packet is noticed, while callers that want ARIA's leniency (the
    optional ``latRatio`` of ``ratioDrive``) ask for it with a default.
    """

    def __init__(self, field: str, needed: int, remaining: int) -> None:
        super().__init__(f"payload ends before field {field!r} ({needed} bytes needed, {remaining} left)")
        self.field = field
        self.needed = needed
        self.remaining = remaining


class PayloadError(ProtocolError):
    """A payload is well framed but its contents do not make sense (bad count, bad value)."""


class MapTooLarge(PayloadError):
    """A map reply went past one of the assembler's bounds (points, segments, lines, bytes).

    Here rather than with the map assemblers (``payloads.mapstream``), so that the reply tracker
    can catch it without importing them (and numpy) into every connection."""

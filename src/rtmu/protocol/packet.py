"""One ArNetworking packet and its exact wire encoding (protocol §1.1–1.4)."""

from __future__ import annotations

import struct
from typing import NamedTuple

from .checksum import checksum
from .errors import PacketTooLong

SYNC = b"\x0f\x0c"
HEADER_LENGTH = 6
FOOTER_LENGTH = 2
MIN_LENGTH = HEADER_LENGTH + FOOTER_LENGTH
MAX_LENGTH = 32000
"""ARIA's ``ArNetPacket::MAX_LENGTH``: the largest total packet, header and checksum included."""
MAX_PAYLOAD = MAX_LENGTH - MIN_LENGTH
"""31992: the largest payload a receiver accepts."""

_HEADER = struct.Struct("<2sHH")


class Packet(NamedTuple):
    """A framed packet: the command number and its payload bytes.

    A named tuple (built in one C call) rather than a frozen dataclass: the decoder makes one per
    packet, a map download hundreds of thousands."""

    command: int
    payload: bytes

    def encode(self) -> bytes:
        return encode_packet(self.command, self.payload)


def encode_packet(command: int, payload: bytes = b"") -> bytes:
    """Frame ``payload`` under ``command`` exactly as ARIA does: sync, length, command, payload, checksum."""
    length = len(payload) + MIN_LENGTH
    if length > MAX_LENGTH:
        raise PacketTooLong(
            f"packet for command {command} would be {length} bytes; ARIA's limit is {MAX_LENGTH} "
            f"(payload at most {MAX_PAYLOAD} bytes, {len(payload)} given)"
        )
    if not 0 <= command <= 0xFFFF:
        raise ValueError(f"command {command} does not fit in an unsigned 16-bit field")
    body = _HEADER.pack(SYNC, length, command) + payload
    c = checksum(body)
    return body + bytes((c >> 8, c & 0xFF))

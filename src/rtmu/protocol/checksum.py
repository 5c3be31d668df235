"""ARIA's packet checksum (``ArNetPacket::calcCheckSum``), exact and fast.

The sum runs over big-endian 16-bit words starting at byte 3 (the high byte of
the length field) and stops before the checksum; one odd byte left over is
XORed in, and for an odd payload the very last payload byte is not covered at
all. Small packets are summed with ``struct`` (C speed, no numpy call
overhead); large ones with numpy, so a 32 KB map packet costs microseconds.
"""

from __future__ import annotations

import struct

import numpy as np

_NUMPY_THRESHOLD = 256
# One precompiled ">nH" per word count below the numpy threshold: a list index is the cheapest lookup.
_WORD_STRUCTS: tuple[struct.Struct, ...] = tuple(struct.Struct(f">{n}H") for n in range(_NUMPY_THRESHOLD))


def checksum(data: bytes | bytearray | memoryview, end: int | None = None, start: int = 0) -> int:
    """Checksum of the packet bytes ``data[start:end]`` (header + payload, no checksum bytes)."""
    if end is None:
        end = len(data)
    covered = end - start - 2  # ARIA's n: bytes from index 3 up to the last payload byte
    if covered <= 3:
        return data[start + 3] if covered > 0 else 0
    words = (covered - 2) >> 1
    first = start + 3
    if words < _NUMPY_THRESHOLD:
        c = sum(_WORD_STRUCTS[words].unpack_from(data, first)) & 0xFFFF
    else:
        c = int(np.frombuffer(data, dtype=">u2", count=words, offset=first).sum(dtype=np.uint64)) & 0xFFFF
    # n ends as 2 or 3, so one byte is always left to XOR in (the last payload byte is skipped when odd).
    return c ^ data[first + 2 * words]


def checksum_naive(data: bytes | bytearray) -> int:
    """The per-byte loop, straight from the protocol document; the benchmark's baseline."""
    c = 0
    i = 3
    n = len(data) - 2
    while n > 3:
        c = (c + (data[i] << 8 | data[i + 1])) & 0xFFFF
        n -= 2
        i += 2
    if n > 0:
        c ^= data[i]
    return c

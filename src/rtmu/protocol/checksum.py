"""ARIA's packet checksum (``ArNetPacket::calcCheckSum``), exact and fast.

The sum runs over big-endian 16-bit words starting at byte 3 (the high byte of
the length field) and stops before the checksum; one odd byte left over is
XORed in, and for an odd payload the very last payload byte is not covered at
all. Small packets are summed with ``struct`` (C speed, no numpy call
overhead); large ones with numpy, so a 32 KB map packet costs microseconds. numpy is not imported
for that alone: until something else has loaded it, packets up to :data:`_STRUCT_LIMIT` words (a
server's data list, a small picture) are summed with ``struct`` too — ~0.2 ms each, against the
50 ms numpy's import adds to a command that never needed it (``rtmu status --once``, the guardian).
"""

from __future__ import annotations

import struct
import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

_NUMPY_THRESHOLD = 256
_STRUCT_LIMIT = 8192
"""Words summed with ``struct`` while numpy is not loaded; a larger packet (a map block, a big
picture) loads it: the command receiving it needs numpy anyway."""
WORD_STRUCTS: tuple[struct.Struct, ...] = tuple(struct.Struct(f">{n}H") for n in range(_NUMPY_THRESHOLD))
"""One precompiled ``>nH`` per word count below the numpy threshold (a tuple index is the cheapest
lookup); the decoder sums small packets with them in its own loop."""


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
        c = sum(WORD_STRUCTS[words].unpack_from(data, first)) & 0xFFFF
    elif words < _STRUCT_LIMIT and "numpy" not in sys.modules:
        c = sum(struct.unpack_from(f">{words}H", data, first)) & 0xFFFF
    else:
        import numpy as np

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


class SpanChecksums:
    """Checksums of any span of a growing buffer in O(1), from prefix sums of its 16-bit words.

    A checksum is a sum of big-endian words, so with ``sums[k]`` = the sum of the words at
    ``base + k - 2``, ``base + k - 4``, … (every other byte offset, both alignments interleaved) the
    sum over a span is one subtraction. The decoder turns this on after a checksum fails: a hostile
    peer can then make it test a 32 000-byte span every few bytes, and summing each span afresh
    would cost 8000 times the bytes received. Extending the sums costs O(new bytes), once each.
    ``stop``: the buffer is summed up to there (exclusive).
    """

    __slots__ = ("_base", "_sums", "_view", "stop")

    def __init__(self) -> None:
        self._base = 0
        self.stop = 0
        self._sums: np.ndarray | None = None
        """Allocated (and numpy imported) by the first :meth:`start`: few decoders ever need it."""
        self._view: memoryview = memoryview(b"")

    def clear(self) -> None:
        """Forget the buffer (it was compacted or emptied); :meth:`start` begins again."""
        self._base = 0
        self.stop = 0

    @property
    def active(self) -> bool:
        return self.stop > self._base

    def start(self, data: bytes | bytearray, base: int, stop: int) -> None:
        """Sum ``data[base:stop]``; later spans must start at ``base`` or after."""
        self._base = self.stop = base
        self.extend(data, stop)

    def extend(self, data: bytes | bytearray, stop: int) -> None:
        """Take ``data[..stop]`` into the sums (the buffer grew; bytes before the old stop unchanged)."""
        import numpy as np

        n0 = self.stop - self._base
        n1 = stop - self._base
        if n1 <= n0:
            return
        sums = self._sums
        if sums is None or n1 + 1 > len(sums):
            grown = np.zeros(max(2 * len(sums) if sums is not None else 0, n1 + 1, 1024), dtype=np.int64)
            if sums is not None:
                kept = min(n0 + 1, len(sums))
                grown[:kept] = sums[:kept]
            self._view.release()
            self._sums = sums = grown
            self._view = grown.data
        # sums[0] and sums[1] are empty sums: zero from np.zeros, never written (entries past a
        # clear()'s stop are only read after being written again, k below starts at 2).
        k = max(n0 + 1, 2)  # first new entry: sums[k] = sums[k - 2] + the word at base + k - 2
        if k <= n1:
            raw = np.frombuffer(data, dtype=np.uint8, count=n1 - k + 2, offset=self._base + k - 2)
            words = raw[:-1].astype(np.int64) << 8 | raw[1:]
            del raw  # a live view of a bytearray would stop it from being resized
            sums[k : n1 + 1 : 2] = sums[k - 2] + np.cumsum(words[0::2])
            sums[k + 1 : n1 + 1 : 2] = sums[k - 1] + np.cumsum(words[1::2])
        self.stop = stop

    def checksum(self, data: bytes | bytearray, end: int, start: int) -> int:
        """Same as ``checksum(data, end, start)`` for a span inside what was summed."""
        covered = end - start - 2
        if covered <= 3:
            return checksum(data, end, start)
        last = start + 3 + ((covered - 2) & ~1)  # the byte XORed in, after the last word
        view = self._view
        base = self._base
        return ((view[last - base] - view[start + 3 - base]) & 0xFFFF) ^ data[last]

"""Incremental, resynchronising packet decoder (protocol §1.8), fed arbitrary chunks.

It follows ARIA's receiver (scan for ``0F 0C``, accept ``8 <= length <= 32000``,
verify the checksum, drop bad packets and keep the connection) and is more
tolerant in two documented ways, so that a valid packet is never lost behind
garbage:

* a failed second sync byte is looked at again as a possible first sync byte;
* after a checksum failure scanning resumes two bytes after the false sync,
  not ``length`` bytes later, so a real packet hidden inside the span that a
  bogus header claimed is still found.

At the end of a stream :meth:`PacketDecoder.close` gives up on a header whose
body never arrived and rescans the bytes behind it.

The second point invites abuse: ``0F 0C 00 7D`` repeated is a fake 32000-byte
header every 4 bytes, and checking each span afresh would cost 8000 times the
bytes received (seconds of CPU per MB). So once a checksum fails, the decoder
keeps prefix sums of the buffer's 16-bit words (:class:`SpanChecksums`) and
checks every further span in O(1) until the buffer is next compacted; a clean
stream never pays for them. Bad packets kept for tools (``keep_bad``) never
overlap, so what they hold is bounded by the bytes fed as well. Total work is
O(bytes fed) for any input.

Nothing in here raises on network input; every dropped byte is counted.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

from .checksum import SpanChecksums, checksum
from .packet import MAX_LENGTH, MIN_LENGTH, SYNC, Packet

_COMPACT_AT = 64 * 1024


@dataclass(slots=True)
class DropStats:
    """What the decoder threw away, and why."""

    garbage_bytes: int = 0
    """Every byte not delivered in a good packet: noise between packets and the bytes of bad
    headers and packets. After :meth:`PacketDecoder.close`, bytes fed = good packets' bytes + this."""
    bad_length: int = 0
    """Headers whose length field was outside 8..32000."""
    bad_checksum: int = 0
    """Complete packets whose checksum did not match."""
    truncated_at_close: int = 0
    """Headers still waiting for their body when the stream ended."""
    packets: int = 0
    """Good packets delivered."""

    @property
    def dropped(self) -> int:
        return self.bad_length + self.bad_checksum + self.truncated_at_close

    def as_dict(self) -> dict[str, int]:
        return {f.name: getattr(self, f.name) for f in fields(self)}


@dataclass(frozen=True, slots=True)
class BadPacket:
    """A framed packet that failed its checksum; reported to tools such as ``rtmu decode``."""

    command: int
    length: int
    raw: bytes


class PacketDecoder:
    """Feed bytes with :meth:`feed`; it returns the good packets found so far.

    Memory is bounded: at most one packet's worth (32000 bytes) plus the last
    chunk is ever held, whatever the peer sends (after a bad checksum, plus 8
    bytes of prefix sums per byte held).
    """

    __slots__ = ("_bad_until", "_buf", "_pos", "_sums", "bad_packets", "keep_bad", "stats")

    def __init__(self, *, keep_bad: bool = False) -> None:
        self._buf = bytearray()
        self._pos = 0
        self._sums = SpanChecksums()
        """Active only after a checksum failed, until the buffer is compacted."""
        self._bad_until = 0
        """Where the last kept bad packet ends in the buffer: the next kept one starts there or later."""
        self.stats = DropStats()
        self.keep_bad = keep_bad
        self.bad_packets: list[BadPacket] = []

    @property
    def buffered(self) -> int:
        """Bytes held while waiting for the rest of a packet."""
        return len(self._buf) - self._pos

    def feed(self, data: bytes | bytearray | memoryview) -> list[Packet]:
        if data:
            self._buf += data
        return self._drain()

    def close(self) -> list[Packet]:
        """End of stream: abandon an incomplete packet and rescan what lies behind its header."""
        found: list[Packet] = []
        while self.buffered >= 2:
            found.extend(self._drain())
            if self.buffered < 2:
                break
            start = self._buf.find(SYNC, self._pos)
            if start < 0:
                break
            self.stats.truncated_at_close += 1
            self.stats.garbage_bytes += start + 2 - self._pos
            self._pos = start + 2
        self.stats.garbage_bytes += self.buffered
        self._buf.clear()
        self._pos = 0
        self._bad_until = 0
        if self._sums.active:
            self._sums.clear()
        return found

    def _drain(self) -> list[Packet]:
        """Take every complete packet out of the buffer (one tight loop: this is the hot path)."""
        buf = self._buf
        find = buf.find
        pos = self._pos
        end = len(buf)
        stats = self.stats
        sums = self._sums
        spans_summed = sums.active
        found: list[Packet] = []
        garbage = 0
        while True:
            start = find(SYNC, pos)
            if start < 0:
                # Keep a trailing 0x0F: it may be the first half of a sync pair.
                keep = 1 if end > pos and buf[end - 1] == 0x0F else 0
                garbage += end - pos - keep
                pos = end - keep
                break
            garbage += start - pos
            pos = start
            if end - pos < 4:
                break
            length = buf[pos + 2] | buf[pos + 3] << 8
            if length < MIN_LENGTH or length > MAX_LENGTH:
                stats.bad_length += 1
                garbage += 4
                pos += 4
                continue
            if end - pos < length:
                break
            body_end = pos + length - 2
            if spans_summed:
                if sums.stop < end:
                    sums.extend(buf, end)
                good = sums.checksum(buf, body_end, pos) == (buf[body_end] << 8 | buf[body_end + 1])
            else:
                good = checksum(buf, body_end, pos) == (buf[body_end] << 8 | buf[body_end + 1])
            if not good:
                stats.bad_checksum += 1
                if not spans_summed:
                    sums.start(buf, pos, end)
                    spans_summed = True
                if self.keep_bad and pos >= self._bad_until:
                    command = buf[pos + 4] | buf[pos + 5] << 8
                    self.bad_packets.append(BadPacket(command, length, bytes(buf[pos : pos + length])))
                    self._bad_until = pos + length
                garbage += 2
                pos += 2
                continue
            found.append(Packet(buf[pos + 4] | buf[pos + 5] << 8, bytes(buf[pos + 6 : body_end])))
            pos += length
        stats.garbage_bytes += garbage
        stats.packets += len(found)
        if pos >= _COMPACT_AT or pos == end:
            del buf[:pos]
            self._bad_until = max(0, self._bad_until - pos)
            pos = 0
            if spans_summed:
                sums.clear()  # offsets moved; the next failure starts afresh from its own position
        self._pos = pos
        return found

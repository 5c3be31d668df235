"""Status packets in bulk: framing, checksums and the typed fields of a whole buffer at once.

A recording, a capture or a fleet's status stream holds status packets by the hundred thousand;
decoding them one :class:`~rtmu.protocol.decoder.PacketDecoder` packet and one
``UpdateNumbers.decode`` at a time costs a few microseconds each, mostly in Python calls. Here the
packets of a buffer are walked once for their lengths; sync bytes, checksums and the fields of every
status packet are then read for all of them together (numpy over the buffer: the checksum from
prefix sums of its 16-bit words, each field from one precompiled layout — :data:`LAYOUT`, the
little-endian ``updateNumbers`` fields — gathered at every packet's offset). The values are the
ones ``UpdateNumbers.decode`` and ``Update.decode`` give, to the bit (tested against them).

:func:`decode_status` takes a buffer of whole packets and the command numbers of its status data
(``updateNumbers``, and ``update``: two strings before the same fields). A buffer the fast path
cannot read as one clean run — a bad sync, length or checksum, a status packet too short for its
fields — is refused (None): its caller decodes it with the packet decoder, which says what was
wrong. Most callers want one packet at a time and use the payload types; this is for bulk.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Final

from .packet import MAX_LENGTH, MIN_LENGTH, Packet

if TYPE_CHECKING:
    import numpy as np

    from .decoder import PacketDecoder
    from .payloads.robot import Update, UpdateNumbers

UPDATE_NUMBERS: Final = "updateNumbers"
UPDATE: Final = "update"
LAYOUT: Final = (("battery", "<i2", 0), ("x", "<i4", 2), ("y", "<i4", 6), ("th", "<i2", 10),
                 ("vel", "<i2", 12), ("rot_vel", "<i2", 14), ("lat_vel", "<i2", 16),
                 ("temperature", "<i1", 18))  # fmt: skip
"""``updateNumbers``' fields: name, little-endian type, offset (19 bytes; ``update`` after its strings)."""
NUMBERS_SIZE: Final = 19


@dataclass(frozen=True, slots=True)
class StatusBatch:
    """The status packets of a buffer, as columns: one entry per status packet, in stream order.

    ``numbers``' fields are those of :class:`~rtmu.protocol.payloads.robot.UpdateNumbers`
    (``battery`` already in volts — or percent — as a float); ``status`` and ``mode`` are the
    ``update`` packets' strings (``""`` for an ``updateNumbers`` packet); ``command`` says which.
    ``packets`` counts every packet of the buffer, status or not.
    """

    command: np.ndarray
    numbers: np.ndarray
    status: np.ndarray
    mode: np.ndarray
    packets: int

    def __len__(self) -> int:
        return len(self.command)

    def numbers_at(self, i: int) -> UpdateNumbers:
        """Entry ``i`` as the payload type (one object: for the few a caller looks at)."""
        from .payloads.robot import UpdateNumbers

        row = self.numbers[i]
        return UpdateNumbers(float(row["battery"]), *(int(row[name]) for name, _, _ in LAYOUT[1:]))

    def update_at(self, i: int) -> Update:
        from .payloads.robot import Update

        return Update(str(self.status[i]), str(self.mode[i]), self.numbers_at(i))


def walk(buf: bytes | bytearray | memoryview) -> tuple[list[int], int]:
    """(start of each whole packet, end of the last) of the back-to-back packets at ``buf``'s start:
    the walk stops at a header that is not one (bad sync or length) or a packet not yet whole.

    Packets of one length in a row (a status stream) are taken a run at a time: their headers are
    checked together, not one Python step each."""
    import numpy as np

    data = np.frombuffer(buf, dtype=np.uint8)
    starts: list[int] = []
    append = starts.append
    pos, size, previous = 0, len(buf), -1
    while size - pos >= MIN_LENGTH and buf[pos] == 0x0F and buf[pos + 1] == 0x0C:
        length = buf[pos + 2] | buf[pos + 3] << 8
        if length < MIN_LENGTH or length > MAX_LENGTH or size - pos < length:
            break
        append(pos)
        pos += length
        if length == previous and size - pos >= RUN_MIN * length:
            run = pos + length * np.arange(min((size - pos) // length, RUN_MAX))
            same = (data[run] == 0x0F) & (data[run + 1] == 0x0C)
            same &= (data[run + 2] == length & 0xFF) & (data[run + 3] == length >> 8)
            taken = int(np.argmin(same)) if not same.all() else len(run)
            starts.extend(run[:taken].tolist())
            pos += taken * length
        previous = length
    return starts, pos


RUN_MIN = 8
"""Packets of one length ahead before their headers are checked as a run."""
RUN_MAX = 1 << 16


def checksums_ok(data: np.ndarray, starts: np.ndarray, lengths: np.ndarray) -> bool:
    """Whether every packet's checksum holds (``protocol.checksum`` for all of them at once).

    The sum of the big-endian words from byte 3 is a difference of prefix sums taken over the words
    at even and at odd offsets; 16-bit sums wrap exactly as ARIA's do.
    """
    import numpy as np

    words = (data[:-1].astype(np.uint16) << 8) | data[1:]
    prefix = np.zeros(len(data) + 1, dtype=np.uint16)  # prefix[i + 2] = word(i) + prefix[i]
    for parity in (0, 1):
        prefix[parity + 2 :: 2][: len(words[parity::2])] = np.cumsum(words[parity::2], dtype=np.uint16)
    covered = lengths - 4  # ARIA's n: bytes from index 3 to the last payload byte (4 or more)
    count = (covered - 2) >> 1  # words summed
    first = starts + 3
    last = first + 2 * (count - 1)  # the last word's offset
    total = prefix[last + 2] - prefix[first]
    odd_byte = data[first + 2 * count]
    expected = (data[starts + lengths - 2].astype(np.uint16) << 8) | data[starts + lengths - 1]
    return bool(np.all((total ^ odd_byte) == expected))


def decode_status(buf: bytes | bytearray | memoryview, commands: Mapping[int, str]) -> StatusBatch | None:
    """Every packet of ``buf`` framed and checked, its status packets decoded (see the module notes).

    ``commands``: command number → data name, for the numbers of ``updateNumbers`` and ``update``
    (other packets are framed, checked and counted only). None when ``buf`` is not a clean run of
    whole packets, or a status packet is too short for its fields.
    """
    starts_list, end = walk(buf)
    if end != len(buf):
        return None
    return _decode(buf, starts_list, commands)


def _decode(
    buf: bytes | bytearray | memoryview, starts_list: list[int], commands: Mapping[int, str]
) -> StatusBatch | None:
    import numpy as np

    data = np.frombuffer(buf, dtype=np.uint8)
    starts = np.asarray(starts_list, dtype=np.int64)
    if not len(starts):
        return _empty(0)
    lengths = (data[starts + 2].astype(np.int64)) | (data[starts + 3].astype(np.int64) << 8)
    command = data[starts + 4].astype(np.int64) | (data[starts + 5].astype(np.int64) << 8)
    if not checksums_ok(data, starts, lengths):
        return None
    numbers_cmd = [c for c, name in commands.items() if name == UPDATE_NUMBERS]
    update_cmd = [c for c, name in commands.items() if name == UPDATE]
    is_numbers = np.isin(command, numbers_cmd)
    is_update = np.isin(command, update_cmd)
    status_mask = is_numbers | is_update
    s = starts[status_mask]
    payload_end = s + lengths[status_mask] - 2
    at = s + 6  # where the fields start: after the strings for ``update``
    upd = is_update[status_mask]
    status = np.full(len(s), "", dtype=object)
    mode = np.full(len(s), "", dtype=object)
    if upd.any():
        zeros = np.flatnonzero(data == 0)
        first = zeros[np.minimum(np.searchsorted(zeros, s[upd] + 6), len(zeros) - 1)]
        second = zeros[np.minimum(np.searchsorted(zeros, first + 1), len(zeros) - 1)]
        if np.any((first < s[upd] + 6) | (second <= first) | (second >= payload_end[upd])):
            return None  # a string runs past the payload: the packet decoder names the field
        status[upd], mode[upd] = _strings(data, s[upd] + 6, first, second)
        at = at.copy()
        at[upd] = second + 1
    if np.any(at + NUMBERS_SIZE > payload_end):
        return None  # too short for the numbers: FieldUnderrun from the payload type
    numbers = np.empty(len(s), dtype=[("battery", "<f8")] + [(name, kind) for name, kind, _ in LAYOUT[1:]])
    for name, kind, offset in LAYOUT:
        column = _gather(data, at + offset, np.dtype(kind))
        numbers[name] = column / 10 if name == "battery" else column
    return StatusBatch(command[status_mask], numbers, status, mode, len(starts))


class StatusStream:
    """Bytes as they arrive (a recording, a capture, a socket read by read) → :class:`StatusBatch`
    columns, with :func:`decode_status`'s values.

    Reads are gathered until :data:`BULK_BYTES` are held, then every whole packet is decoded at
    once; the bytes of a packet not yet whole wait for the next feed. A stretch the fast path
    refuses (garbage, a bad checksum, a lying header, a malformed status packet) goes through the
    :class:`~rtmu.protocol.decoder.PacketDecoder` and the payload types until that decoder holds
    nothing again; a status packet they cannot read is counted in :attr:`malformed` and left out.
    """

    def __init__(self, commands: Mapping[int, str], *, bulk_bytes: int = 0) -> None:
        self.commands = dict(commands)
        self.bulk_bytes = bulk_bytes or BULK_BYTES
        self.malformed = 0
        self._held = bytearray()
        self._slow: PacketDecoder | None = None

    def feed(self, data: bytes | bytearray | memoryview) -> StatusBatch | None:
        """The status packets completed by ``data`` (None while gathering)."""
        if self._slow is not None:
            batch = self._packets(self._slow.feed(data))
            if not self._slow.buffered:
                self._slow = None
            return batch
        self._held += data
        if len(self._held) < self.bulk_bytes:
            return None
        return self._flush()

    def close(self) -> StatusBatch:
        """End of the stream: what is held is decoded; a packet cut short is dropped."""
        from .decoder import PacketDecoder

        decoder, self._slow = self._slow or PacketDecoder(), None
        held, self._held = bytes(self._held), bytearray()
        return self._packets([*decoder.feed(held), *decoder.close()])

    def _flush(self) -> StatusBatch:
        held = self._held
        starts, end = walk(held)
        batch = _decode(memoryview(held)[:end], starts, self.commands) if starts else None
        if batch is None or len(held) - end > MAX_WAITING:  # not a clean run: the packet decoder
            from .decoder import PacketDecoder

            self._held = bytearray()
            self._slow = PacketDecoder()
            batch = self._packets(self._slow.feed(held))
            if not self._slow.buffered:
                self._slow = None
            return batch
        del held[:end]
        return batch

    def _packets(self, packets: list[Packet]) -> StatusBatch:
        """The payload types' values, as columns (the slow path)."""
        import numpy as np

        from .errors import ProtocolError
        from .payloads.robot import Update, UpdateNumbers

        rows: list[tuple[int, UpdateNumbers, str, str]] = []
        for command, payload in packets:
            name = self.commands.get(command)
            try:
                if name == UPDATE_NUMBERS:
                    rows.append((command, UpdateNumbers.decode(payload), "", ""))
                elif name == UPDATE:
                    update = Update.decode(payload)
                    rows.append((command, update.numbers, update.status, update.mode))
            except ProtocolError:
                self.malformed += 1
        batch = _empty(len(packets))
        if not rows:
            return batch
        numbers = np.array(
            [(n.battery, n.x, n.y, n.th, n.vel, n.rot_vel, n.lat_vel, n.temperature) for _, n, _, _ in rows],
            dtype=batch.numbers.dtype,
        )
        status = np.empty(len(rows), dtype=object)
        mode = np.empty(len(rows), dtype=object)
        status[:] = [r[2] for r in rows]
        mode[:] = [r[3] for r in rows]
        return StatusBatch(
            np.array([r[0] for r in rows], dtype=np.int64), numbers, status, mode, len(packets)
        )


BULK_BYTES: Final = 8192
"""Bytes gathered before a bulk decode: numpy's fixed cost per call is then a fraction of a
microsecond a packet."""
MAX_WAITING: Final = 1024
"""A packet not yet whole after a bulk decode, longer than this (a map block, or a header that lies),
is the packet decoder's to wait for: it can tell a liar from a big packet."""


def _gather(data: np.ndarray, offsets: np.ndarray, kind: np.dtype) -> np.ndarray:
    """The little-endian integers of type ``kind`` at ``offsets`` (any alignment)."""
    import numpy as np

    value = np.zeros(len(offsets), dtype=np.int64)
    for k in range(kind.itemsize):
        value |= data[offsets + k].astype(np.int64) << (8 * k)
    bits = 8 * kind.itemsize
    return (value ^ (1 << (bits - 1))) - (1 << (bits - 1))  # two's complement


def _strings(
    data: np.ndarray, begin: np.ndarray, first: np.ndarray, second: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The two strings of each ``update`` packet, as latin-1 text: each distinct pair decoded once
    (a status stream repeats a handful of words), found again by a hash of its bytes (a collision
    is caught: then every pair is decoded on its own)."""
    import numpy as np

    from .fields import TEXT_ENCODING

    width = -(-(int((second - begin).max()) + 1) // 8) * 8  # whole 8-byte words
    window = begin[:, None] + np.arange(width)
    inside = window <= second[:, None]
    rows = np.where(inside, data[np.minimum(window, len(data) - 1)], 0).astype(np.uint8)
    words = rows.view(np.uint64)
    key = np.zeros(len(rows), dtype=np.uint64)
    for column in words.T:  # a polynomial hash of the row, wrapping
        key = key * np.uint64(0x100000001B3) ^ column
    _, first_of, inverse = np.unique(key, return_index=True, return_inverse=True)
    unique = rows[first_of]
    if not np.array_equal(unique[inverse], rows):  # two different pairs, one hash
        unique, inverse = rows, np.arange(len(rows))
    texts = [row.tobytes().split(b"\0", 2)[:2] for row in unique]
    status = np.array([t[0].decode(TEXT_ENCODING) for t in texts], dtype=object)[inverse]
    mode = np.array([t[1].decode(TEXT_ENCODING) for t in texts], dtype=object)[inverse]
    return status, mode


def _empty(packets: int) -> StatusBatch:
    import numpy as np

    dtype = [("battery", "<f8")] + [(name, kind) for name, kind, _ in LAYOUT[1:]]
    return StatusBatch(
        np.zeros(0, np.int64), np.zeros(0, dtype), np.zeros(0, object), np.zeros(0, object), packets
    )

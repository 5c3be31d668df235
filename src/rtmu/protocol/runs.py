"""Runs of back-to-back packets of one length and command — a status stream — framed together.

The decoder's general loop (:mod:`.decoder`) costs about a microsecond of Python per packet: find the
sync, read the length, sum the checksum, branch on every rule. A status stream is a run of packets
that share their first six bytes (sync, length, command); once the general loop has framed one and
the next has the same length, :func:`take_run` takes the rest of the run:

* one packet at a time, with one precompiled ``struct`` layout of the checksum's words per length;
* then, for a long run with many already here (a burst, a recording, a capture: :data:`BLOCK_MIN`
  packets, :data:`IMPORT_AT` if numpy is not loaded yet), in growing blocks — the buffer seen by
  numpy as a table of rows, one packet a row, headers compared and checksums summed column-wise.

A run stops at the first packet that differs in any way — another header, a bad checksum, a packet
not yet whole — and that packet is the general loop's, which applies every rule (resync, lying
headers, drop counts) as before: the packets delivered are the same, in the same order
(``tests/protocol/test_status_fast_path.py`` checks this against the general loop alone).
"""

from __future__ import annotations

import struct
import sys
from itertools import repeat
from typing import Final

from .packet import Packet

BLOCK_MIN: Final = 16
"""Packets of a run taken one by one before the rest is taken in blocks (numpy), if this many more
are already in the buffer."""
IMPORT_AT: Final = 256
"""…and from which numpy is imported for this (its import costs ~50 ms; a live status stream never
brings that many at once, a burst or a recording does)."""

_new_tuple = tuple.__new__
_LAYOUTS: dict[int, tuple[struct.Struct, int]] = {}
"""Packet length → its precompiled layout from byte 3 (the checksum's words, the byte XORed in,
the checksum) and the index of that XORed byte in what it unpacks."""


def _layout(length: int) -> tuple[struct.Struct, int]:
    words = (length - 6) >> 1  # as checksum(): the words from byte 3, then one byte XORed in
    skipped = length - 2 - (3 + 2 * words + 1)  # an odd payload's last byte is not summed
    layout = _LAYOUTS[length] = (struct.Struct(f">{words}HB{skipped}xH"), words)
    return layout


def take_run(buf: bytes, pos: int, end: int, length: int, found: list[Packet]) -> int:
    """Frame the packets at ``pos`` that share its first six bytes and are whole and checksum-correct
    into ``found``; return where the run stopped (``pos``: not even one).

    The caller has checked that ``buf[pos:]`` starts with a sync pair and ``length``. The first
    :data:`BLOCK_MIN` go one by one (most runs in a map or a mixed stream are short: a block would
    look at the whole buffer for two packets); a run still going on is then taken in blocks four
    times longer each time, so no more than about the run itself is ever looked at."""
    head = buf[pos : pos + 6]
    start = pos
    pos = _take_each(buf, pos, min(end, pos + BLOCK_MIN * length), length, head, found)
    if pos - start < BLOCK_MIN * length:
        return pos  # the run ended, or the buffer did
    block = 4 * BLOCK_MIN
    while (ahead := (end - pos) // length) >= BLOCK_MIN and (ahead >= IMPORT_AT or "numpy" in sys.modules):
        count = min(ahead, block)
        taken = _take_block(buf, pos, count, length, head, found)
        pos += taken * length
        if taken < count:
            return pos
        block *= 4
    return _take_each(buf, pos, end, length, head, found)


def _take_each(buf: bytes, pos: int, end: int, length: int, head: bytes, found: list[Packet]) -> int:
    """:func:`take_run` one packet at a time, up to ``end``."""
    layout = _LAYOUTS.get(length) or _layout(length)
    unpack = layout[0].unpack_from
    odd_at = layout[1]
    command = head[4] | head[5] << 8
    same_head = buf.startswith
    append = found.append
    new_packet = _new_tuple
    last_start = end - length
    body = length - 2
    while pos <= last_start and same_head(head, pos):
        t = unpack(buf, pos + 3)
        odd = t[odd_at]
        sent = t[-1]
        if (sum(t) - odd - sent) & 0xFFFF ^ odd != sent:
            break
        append(new_packet(Packet, (command, buf[pos + 6 : pos + body])))
        pos += length
    return pos


def _take_block(buf: bytes, pos: int, count: int, length: int, head: bytes, found: list[Packet]) -> int:
    """:func:`take_run` for ``count`` whole packets at once: how many leading ones match ``head``
    and their checksums (those are taken)."""
    import numpy as np

    rows = np.frombuffer(buf, np.uint8, count * length, pos).reshape(count, length)
    same = (rows[:, :6] == np.frombuffer(head, np.uint8)).all(axis=1)
    words = (length - 6) >> 1
    high = rows[:, 3 : 3 + 2 * words : 2].astype(np.uint16) << 8
    total = (high | rows[:, 4 : 4 + 2 * words : 2]).sum(axis=1, dtype=np.uint16)  # wraps as ARIA's
    sent = rows[:, length - 2].astype(np.uint16) << 8 | rows[:, length - 1]
    good = same & ((total ^ rows[:, 3 + 2 * words]) == sent)
    taken = count if good.all() else int(good.argmin())
    first = pos + 6
    size = length - 8
    payloads = [buf[at : at + size] for at in range(first, first + taken * length, length)]
    command = head[4] | head[5] << 8
    found.extend(map(_new_tuple, repeat(Packet, taken), zip(repeat(command, taken), payloads, strict=True)))
    return taken

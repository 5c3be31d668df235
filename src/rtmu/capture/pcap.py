"""Read link-layer frames from classic libpcap and pcapng files, one at a time.

Both byte orders, microsecond and nanosecond pcap, pcapng with several
interfaces and ``if_tsresol``. Frames are streamed from the file, so memory
stays bounded whatever the capture size. A file cut short (tcpdump killed
mid-write) ends the frames with a warning rather than an error.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from dataclasses import dataclass
from typing import BinaryIO

from .base import CaptureError

PCAP_MAGICS = {
    b"\xd4\xc3\xb2\xa1": ("<", 1e-6),
    b"\xa1\xb2\xc3\xd4": (">", 1e-6),
    b"\x4d\x3c\xb2\xa1": ("<", 1e-9),
    b"\xa1\xb2\x3c\x4d": (">", 1e-9),
}
PCAPNG_MAGIC = b"\x0a\x0d\x0d\x0a"
MAX_FRAME = 1 << 20
"""A record larger than this is a damaged file, not a frame (jumbo + headers stay far below)."""


@dataclass(frozen=True, slots=True)
class Frame:
    time: float
    link_type: int
    data: bytes
    original_length: int


class FrameReader:
    """Iterate over :class:`Frame`; problems that stop reading land in ``warnings``."""

    kind = "pcap"

    def __init__(self, stream: BinaryIO) -> None:
        self._f = stream
        self.warnings: list[str] = []
        self.link_types: set[int] = set()

    def __iter__(self) -> Iterator[Frame]:
        raise NotImplementedError

    def _read(self, size: int, what: str) -> bytes | None:
        data = self._f.read(size)
        if len(data) == size:
            return data
        if data:
            self.warnings.append(f"capture ends in the middle of {what}: the file was cut short")
        return None


class PcapReader(FrameReader):
    def __init__(self, stream: BinaryIO, header: bytes) -> None:
        super().__init__(stream)
        magic = header[:4]
        if magic not in PCAP_MAGICS:
            raise CaptureError("not a pcap file (unknown magic number)")
        if len(header) < 24:
            raise CaptureError("pcap file too short to hold its 24-byte header")
        self._order, self._unit = PCAP_MAGICS[magic]
        major, _minor, _zone, _sigfigs, self.snaplen, network = struct.unpack(
            self._order + "HHiIII", header[4:24]
        )
        if major != 2:
            raise CaptureError(f"pcap version {major} is not supported (only version 2 exists in practice)")
        self.link_type = network & 0xFFFF  # the upper bits carry FCS information
        self.link_types.add(self.link_type)
        self._record = struct.Struct(self._order + "IIII")

    def __iter__(self) -> Iterator[Frame]:
        record = self._record
        unit = self._unit
        link = self.link_type
        limit = max(self.snaplen, MAX_FRAME)
        while True:
            head = self._read(16, "a record header")
            if head is None:
                return
            sec, frac, incl, orig = record.unpack(head)
            if incl > limit:
                self.warnings.append(f"damaged record claims {incl} bytes; reading stopped there")
                return
            data = self._read(incl, "a frame")
            if data is None:
                return
            yield Frame(sec + frac * unit, link, data, orig)


class PcapngReader(FrameReader):
    kind = "pcapng"

    def __init__(self, stream: BinaryIO) -> None:
        super().__init__(stream)
        self._order = "<"
        self._interfaces: list[tuple[int, float]] = []  # (link type, seconds per tick)

    def __iter__(self) -> Iterator[Frame]:
        while True:
            head = self._read(8, "a block header")
            if head is None:
                return
            if head[:4] == PCAPNG_MAGIC:
                bom = self._read(4, "a section header")
                if bom is None:
                    return
                if bom == b"\x4d\x3c\x2b\x1a":
                    self._order = "<"
                elif bom == b"\x1a\x2b\x3c\x4d":
                    self._order = ">"
                else:
                    raise CaptureError("pcapng section header has an unknown byte-order magic")
                self._interfaces = []
                (length,) = struct.unpack(self._order + "I", head[4:])
                body = self._body(length, 12)
            else:
                block_type, length = struct.unpack(self._order + "II", head)
                body = self._body(length, 8)
                if body is None:
                    return
                try:
                    frame = self._block(block_type, body)
                except (struct.error, IndexError):
                    self.warnings.append(f"damaged pcapng block of type {block_type}; reading stopped there")
                    return
                if frame is not None:
                    yield frame
            if body is None:
                return

    def _body(self, length: int, consumed: int) -> bytes | None:
        if length < consumed + 4 or length % 4 or length > MAX_FRAME + 64:
            self.warnings.append(f"damaged pcapng block of {length} bytes; reading stopped there")
            return None
        data = self._read(length - consumed, "a block")
        return None if data is None else data[:-4]  # the trailing copy of the length

    def _block(self, block_type: int, body: bytes) -> Frame | None:
        o = self._order
        if block_type == 1:  # interface description
            link, _reserved, _snap = struct.unpack(o + "HHI", body[:8])
            self._interfaces.append((link, _tsresol(body[8:], o)))
            self.link_types.add(link)
            return None
        if block_type == 6 and len(body) >= 20:  # enhanced packet
            iface, high, low, cap, orig = struct.unpack(o + "IIIII", body[:20])
            link, unit = self._interface(iface)
            return Frame(((high << 32) | low) * unit, link, body[20 : 20 + cap], orig)
        if block_type == 3 and len(body) >= 4:  # simple packet: no timestamp
            (orig,) = struct.unpack(o + "I", body[:4])
            link, _unit = self._interface(0)
            return Frame(0.0, link, body[4 : 4 + orig], orig)
        if block_type == 2 and len(body) >= 20:  # obsolete packet block
            iface, _drops, high, low, cap, orig = struct.unpack(o + "HHIIII", body[:20])
            link, unit = self._interface(iface)
            return Frame(((high << 32) | low) * unit, link, body[20 : 20 + cap], orig)
        return None

    def _interface(self, index: int) -> tuple[int, float]:
        if index >= len(self._interfaces):
            raise CaptureError(f"pcapng packet refers to interface {index}, which was never described")
        return self._interfaces[index]


def _tsresol(options: bytes, order: str) -> float:
    """Seconds per timestamp tick from the ``if_tsresol`` option (default microseconds)."""
    pos = 0
    while pos + 4 <= len(options):
        code, length = struct.unpack(order + "HH", options[pos : pos + 4])
        if code == 0:
            break
        if code == 9 and length >= 1 and pos + 4 < len(options):
            value = options[pos + 4]
            return 2.0 ** -(value & 0x7F) if value & 0x80 else 10.0**-value
        pos += 4 + (length + 3) // 4 * 4
    return 1e-6

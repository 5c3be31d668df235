"""Open any supported input and turn it into capture events (see :mod:`rtmu.capture.base`).

Formats: classic pcap and pcapng (TCP reassembled on any port, UDP datagrams
passed through), an RTMU recording (MCAP: its raw channel, see ``recorded``), a hex
dump, or raw bytes (one stream each). ``auto`` picks by
content: pcap magic numbers first, then text that parses as hex, then binary
that contains ArNetworking's ``0F 0C`` sync pair.
"""

from __future__ import annotations

import io
import struct
from collections.abc import Iterator
from pathlib import Path

from .base import CaptureError, CaptureEvent, CaptureStats, Datagram, Endpoint, Flow, StreamData, StreamEnd
from .choices import DIRECTIONS, FORMATS
from .hexdump import parse_hex
from .net import SUPPORTED_LINK_TYPES, TCP, NotTcpUdp, ip_payload, parse_ip
from .pcap import PCAP_MAGICS, PCAPNG_MAGIC, FrameReader, PcapngReader, PcapReader
from .recorded import MCAP_MAGIC, recorded_events
from .tcp import TcpReassembler

CHUNK = 64 * 1024
_TEXT_BYTES = frozenset(range(0x20, 0x7F)) | frozenset(b"\t\n\r\f\v")
SYNC = b"\x0f\x0c"

STREAM_SENDER = Endpoint("sender", 0)
STREAM_RECEIVER = Endpoint("receiver", 0)


class UnreadableInput(CaptureError):
    """The file cannot be opened or read at all."""


class CaptureSource:
    """One input file, ready to be iterated with :meth:`events` (once)."""

    def __init__(self, path: Path, kind: str, direction: str = "auto") -> None:
        self.path = path
        self.kind = kind
        self.direction = direction
        self.stats = CaptureStats(kind=kind)

    def events(self) -> Iterator[CaptureEvent]:
        if self.kind in ("pcap", "pcapng"):
            return self._pcap_events()
        if self.kind == "mcap":
            return recorded_events(self.path, self.stats)
        return self._stream_events()

    # -- pcap / pcapng ---------------------------------------------------------
    def _pcap_events(self) -> Iterator[CaptureEvent]:
        stats = self.stats
        tcp = TcpReassembler(stats)
        with _open(self.path) as f:
            head = f.read(24)
            reader: FrameReader
            if head[:4] == PCAPNG_MAGIC:
                reader = PcapngReader(f)
                f.seek(0)
            else:
                reader = pcap = PcapReader(f, head)
                stats.link_type = pcap.link_type
            last = None
            unsupported: set[int] = set()
            for frame in reader:
                stats.frames += 1
                if stats.first_time is None:
                    stats.first_time = frame.time
                last = frame.time
                if frame.link_type not in SUPPORTED_LINK_TYPES:
                    unsupported.add(frame.link_type)
                    stats.not_ip += 1
                    continue
                cut = max(0, frame.original_length - len(frame.data))
                if cut:
                    stats.truncated_frames += 1
                try:
                    seg = parse_ip(ip_payload(frame.link_type, frame.data), cut)
                except NotTcpUdp as exc:
                    if str(exc) == "IP fragment":
                        stats.ip_fragments += 1
                    else:
                        stats.not_ip += 1
                    continue
                except (IndexError, ValueError, struct.error):
                    stats.not_ip += 1  # a mangled header: skip the frame, keep reading
                    continue
                if seg.protocol == TCP:
                    yield from tcp.segment(seg, frame.time)
                else:
                    yield Datagram(seg.src, seg.dst, frame.time, seg.payload, truncated=seg.lost > 0)
            stats.last_time = last
            stats.warnings.extend(reader.warnings)
            stats.warnings.extend(
                f"link type {lt} is not supported; its frames were skipped" for lt in sorted(unsupported)
            )
            if stats.link_type is None and len(reader.link_types) == 1:
                stats.link_type = next(iter(reader.link_types))
        yield from tcp.finish(last)

    # -- hex dump / raw bytes --------------------------------------------------------
    def _flow(self) -> Flow:
        flow = Flow(1, "stream", STREAM_SENDER, STREAM_RECEIVER)
        if self.direction == "s2c":
            flow.server = STREAM_SENDER
        elif self.direction == "c2s":
            flow.server = STREAM_RECEIVER
        return flow

    def _stream_events(self) -> Iterator[CaptureEvent]:
        flow = self._flow()
        chunks = self._hex_chunks() if self.kind == "hex" else self._raw_chunks()
        for chunk in chunks:
            yield StreamData(flow, STREAM_SENDER, None, chunk)
        yield StreamEnd(flow, STREAM_SENDER, None)

    def _raw_chunks(self) -> Iterator[bytes]:
        with _open(self.path) as f:
            while chunk := f.read(CHUNK):
                yield chunk

    def _hex_chunks(self) -> Iterator[bytes]:
        buf = bytearray()
        with _open_text(self.path) as f:
            for data in parse_hex(f):
                buf += data
                if len(buf) >= CHUNK:
                    yield bytes(buf)
                    buf.clear()
        if buf:
            yield bytes(buf)


def _open(path: Path):
    try:
        return path.open("rb")
    except OSError as exc:
        raise UnreadableInput(f"cannot read {path}: {exc.strerror or exc}") from exc


def _open_text(path: Path):
    try:
        return path.open("r", encoding="latin-1", newline=None)
    except OSError as exc:
        raise UnreadableInput(f"cannot read {path}: {exc.strerror or exc}") from exc


def open_capture(path: str | Path, fmt: str = "auto", direction: str = "auto") -> CaptureSource:
    """Check the input and decide its format; raises :class:`CaptureError` with one clear sentence."""
    path = Path(path)
    if fmt not in FORMATS:
        raise CaptureError(f"unknown input format {fmt!r} (choose from {', '.join(FORMATS)})")
    if direction not in DIRECTIONS:
        raise CaptureError(f"unknown direction {direction!r} (choose from {', '.join(DIRECTIONS)})")
    if path.is_dir():
        raise UnreadableInput(f"cannot read {path}: it is a directory")
    with _open(path) as f:
        try:
            sample = f.read(CHUNK)
        except OSError as exc:
            raise UnreadableInput(f"cannot read {path}: {exc.strerror or exc}") from exc
    magic = sample[:4]
    if fmt in ("auto", "pcap"):
        if magic in PCAP_MAGICS:
            if len(sample) < 24:
                raise CaptureError(f"{path} is cut short: a pcap header needs 24 bytes")
            header = PcapReader(io.BytesIO(sample), sample[:24])  # validates version and header
            if header.link_type not in SUPPORTED_LINK_TYPES:
                raise CaptureError(
                    f"{path}: link type {header.link_type} is not supported "
                    "(Ethernet, BSD loopback, raw IP, Linux cooked SLL/SLL2)"
                )
            source = CaptureSource(path, "pcap")
            source.stats.link_type = header.link_type
            return source
        if magic == PCAPNG_MAGIC:
            return CaptureSource(path, "pcapng")
        if sample.startswith(MCAP_MAGIC):  # an RTMU recording (rtmu.recorder): its raw channel
            return CaptureSource(path, "mcap")
        if fmt == "pcap":
            raise CaptureError(f"{path} is not a pcap or pcapng file (unknown magic number {magic.hex()})")
    if not sample:
        raise CaptureError(f"{path} is empty")
    if fmt == "raw":
        return CaptureSource(path, "raw", direction)
    looks_text = all(b in _TEXT_BYTES for b in sample)
    if fmt == "hex" or looks_text:
        try:
            with _open_text(path) as f:
                for _ in parse_hex(f):
                    pass
        except CaptureError as exc:
            if fmt == "hex":
                raise
            raise CaptureError(f"{path} is text but not a hex dump: {exc}") from None
        return CaptureSource(path, "hex", direction)
    if not _has_sync(path):
        raise CaptureError(
            f"{path} is not a recognised format: not pcap/pcapng, not a hex dump, "
            "and no ArNetworking sync bytes (0F 0C) in it"
        )
    return CaptureSource(path, "raw", direction)


def _has_sync(path: Path) -> bool:
    with _open(path) as f:
        tail = b""
        while chunk := f.read(CHUNK):
            if SYNC in tail + chunk:
                return True
            tail = chunk[-1:]
    return False

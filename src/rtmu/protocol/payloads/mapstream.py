"""Whole maps over the wire (protocol §4.5): sans-I/O assemblers for the client, packet series for the server.

Client side: create an assembler when sending ``getMap`` / ``getMapBinary``,
:meth:`feed` it the payload of every reply packet for that data, and take
:meth:`result` once ``feed`` returns True. Nothing is trusted: each assembler
bounds what it will hold (lines, bytes, points) and raises :class:`MapTooLarge`
or :class:`~rtmu.protocol.errors.PayloadError` instead of growing without end.

Server side: :func:`map_text_payloads` and :func:`map_binary_payloads` turn a
map (already parsed by :mod:`rtmu.mapfile`) into the payloads ARIA would send.
"""

from __future__ import annotations

import struct
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from enum import Enum, auto
from typing import Final

import numpy as np

from ..errors import PayloadError
from ..fields import TEXT_ENCODING, FieldReader, FieldWriter
from ..packet import MAX_PAYLOAD
from .map import COORD_DTYPE, POINT_BYTES, SEGMENT_BYTES, binary_block_kind, coords_bytes, read_block

MAX_ITEMS_PER_PACKET: Final = 1000
"""ARIA puts at most 1000 points or segments in one binary packet."""
# Bounds from what a map can be, so that an endless or huge stream fails in seconds and costs at most
# tens of MB (text maps above a million lines need getMapBinary, offered since ARIA 2.7).
# ARIA's and ARAM's large site maps hold a few hundred thousand to ~2 million points, a
# few thousand lines and tens of thousands of header lines (cairns, info). As int32 pairs the point
# cap is 40 MB, the segment cap 16 MB; text is kept as bytes, one per character plus a separator.
DEFAULT_MAX_POINTS: Final = 5_000_000
DEFAULT_MAX_SEGMENTS: Final = 1_000_000
DEFAULT_MAX_HEADER_LINES: Final = 200_000
DEFAULT_MAX_HEADER_BYTES: Final = 32 * 1024 * 1024
DEFAULT_MAX_TEXT_LINES: Final = 1_000_000
DEFAULT_MAX_TEXT_BYTES: Final = 48 * 1024 * 1024

_COUNT = struct.Struct("<i")
_BLOCK_END: Final = _COUNT.pack(0)
_EMPTY_STRING: Final = b"\x00"


class MapTooLarge(PayloadError):
    """A map reply went past one of the assembler's bounds (points, segments, lines, bytes)."""


class ReplyAlreadyComplete(PayloadError):
    """A packet arrived for a map reply that had already ended."""


class _Claims:
    """What the header says the map holds (``NumPoints:``, ``NumLines:``), as a bound on the stream.

    A server that streams points for ever behind an honest header is stopped just past its own
    count, in a fraction of a second, long before the absolute caps. ARIA writes these counts from
    the real data; a slack of 10 % (at least 1000) forgives a hand-edited header.
    """

    def __init__(self) -> None:
        self.points: int | None = None
        self.lines: int | None = None

    def note(self, line: bytes | str) -> None:
        raw = line.encode(TEXT_ENCODING, "replace") if isinstance(line, str) else line
        for key, attr in ((b"NumPoints:", "points"), (b"NumLines:", "lines")):
            if raw.startswith(key):
                try:
                    value = int(raw[len(key) :].split()[0])
                except (ValueError, IndexError):
                    return
                if value >= 0:
                    setattr(self, attr, value)

    @staticmethod
    def over(claimed: int | None, count: int) -> bool:
        return claimed is not None and count > claimed + max(1000, claimed // 10)


def _text(payload: bytes) -> str:
    return FieldReader(payload).string("map line")


# -- getMap: text lines ---------------------------------------------------------------


@dataclass
class TextMap:
    """A ``getMap`` reply: the map file's text (lines joined by ``\\n``, as ARIA's file has them)."""

    text: bytes = b""
    line_count: int = 0
    has_map: bool = True

    @property
    def lines(self) -> list[str]:
        """The lines as text (for small maps and tests; the map parser reads :attr:`text`)."""
        return self.text.decode(TEXT_ENCODING).split("\n") if self.line_count else []


class MapTextAssembler:
    """Collects a ``getMap`` reply: line packets, ``""`` (end of map), then a zero-length packet.

    A lone ``""`` before any line means the server has no map; ARIA sends
    nothing after it, so that ends the reply too. Lines are kept as bytes in one
    buffer, not as a list of strings: a million-line map costs its size in bytes,
    not ~60 bytes of object per line.
    """

    def __init__(
        self, *, max_lines: int = DEFAULT_MAX_TEXT_LINES, max_bytes: int = DEFAULT_MAX_TEXT_BYTES
    ) -> None:
        self.max_lines = max_lines
        self.max_bytes = max_bytes
        self._text = bytearray()
        self._count = 0
        self._claims = _Claims()
        self._section = b""
        self._in_section = 0
        self._end_of_map = False
        self.done = False
        self.has_map = True

    def feed(self, payload: bytes) -> bool:
        """Take one reply payload; True once the reply is complete."""
        if self.done:
            raise ReplyAlreadyComplete("getMap reply already complete")
        if not payload:
            self.done = True
            self.has_map = self._count > 0
            return True
        if self._end_of_map:
            raise PayloadError("getMap: only the final empty packet may follow the end of the map")
        end = payload.find(b"\0")
        line = payload if end < 0 else payload[:end]  # an unterminated string runs to the end
        if not line:
            self._end_of_map = True
            if not self._count:  # no map: ARIA sends only this packet
                self.has_map = False
                self.done = True
            return self.done
        if self._count >= self.max_lines:
            raise MapTooLarge(f"getMap: more than {self.max_lines} lines")
        if len(self._text) + len(line) + 1 > self.max_bytes:
            raise MapTooLarge(f"getMap: more than {self.max_bytes} bytes of text")
        if b"\n" in line or b"\r" in line:
            raise PayloadError(f"getMap: line {self._count + 1} contains a line break")
        self._check_claims(line)
        if self._count:
            self._text += b"\n"
        self._text += line
        self._count += 1
        return False

    def _check_claims(self, line: bytes) -> None:
        if line in (b"LINES", b"DATA"):
            self._section, self._in_section = line, 0
            return
        if not self._section:
            self._claims.note(line)
            return
        if line[:1].isalpha() and b":" not in line and b" " not in line:
            self._section = b""  # another (scan-prefixed) section: only the absolute caps apply
            return
        self._in_section += 1
        claimed, what = (
            (self._claims.points, "points") if self._section == b"DATA" else (self._claims.lines, "lines")
        )
        if _Claims.over(claimed, self._in_section):
            raise MapTooLarge(f"getMap: more {what} than the map's header says ({claimed})")

    @property
    def line_count(self) -> int:
        return self._count

    @property
    def lines(self) -> list[str]:
        return TextMap(bytes(self._text), self._count).lines

    def result(self) -> TextMap:
        if not self.done:
            raise PayloadError("getMap reply is not complete yet")
        return TextMap(bytes(self._text), self._count, self.has_map)


def map_text_payloads(lines: Iterable[str] | None) -> list[bytes]:
    """The ``getMap`` reply payloads for a map's lines; None (or no lines) = the server has no map."""
    out = [FieldWriter().string(_checked_line(line)).bytes() for line in lines or ()]
    if not out:
        return [_EMPTY_STRING]
    out.append(_EMPTY_STRING)
    out.append(b"")
    return out


def _checked_line(line: str) -> str:
    if line == "":
        raise ValueError("an empty map line would end the map early on the wire")
    if "\n" in line or "\r" in line:
        raise ValueError(f"map line contains a line break: {line[:40]!r}")
    if len(line) >= MAX_PAYLOAD:
        raise ValueError(f"map line of {len(line)} characters does not fit in one packet")
    return line


# -- getMapBinary: text header, binary geometry ---------------------------------------


@dataclass(eq=False)
class BinaryMap:
    """A ``getMapBinary`` reply: header/object lines and the geometry as int32 arrays (mm)."""

    header_lines: list[str]
    segments: np.ndarray
    """``(n, 4)`` int32: x1, y1, x2, y2."""
    points: np.ndarray
    """``(n, 2)`` int32: x, y."""
    has_map: bool = True


class _State(Enum):
    HEADER = auto()
    SEGMENTS = auto()
    POINTS = auto()
    BETWEEN = auto()
    """After a ``byte4 0``: another section keyword or the end."""
    AFTER_EMPTY = auto()
    """After ``""`` (lines-only server): only the zero-length packet may follow."""
    DONE = auto()


def _section(keyword: str) -> _State | None:
    """``LINES`` / ``DATA`` (and the scan-prefixed ``<Scan>_LINES`` of ``getMapWithMaxCategory``)."""
    if " " in keyword or ":" in keyword:
        return None  # header and object lines always hold "Keyword: values"
    if keyword == "LINES" or keyword.endswith("_LINES"):
        return _State.SEGMENTS
    if keyword == "DATA" or keyword.endswith("_DATA"):
        return _State.POINTS
    return None


class MapBinaryAssembler:
    """Collects a ``getMapBinary`` reply (also fits ``getMapWithMaxCategory``, scans merged).

    Sequence: header text packets; optionally ``"LINES"`` then segment blocks
    then ``byte4 0``; ``"DATA"`` then point blocks then ``byte4 0`` (or ``""``
    from a lines-only server); a zero-length packet. A lone ``""`` = no map.
    Blocks are kept as bytes and become arrays once, with ``numpy.frombuffer``.
    """

    def __init__(
        self,
        *,
        max_points: int = DEFAULT_MAX_POINTS,
        max_segments: int = DEFAULT_MAX_SEGMENTS,
        max_header_lines: int = DEFAULT_MAX_HEADER_LINES,
        max_header_bytes: int = DEFAULT_MAX_HEADER_BYTES,
    ) -> None:
        self.max_points = max_points
        self.max_segments = max_segments
        self.max_header_lines = max_header_lines
        self.max_header_bytes = max_header_bytes
        self.header_lines: list[str] = []
        self._header_bytes = 0
        self._segment_chunks: list[bytes] = []
        self._point_chunks: list[bytes] = []
        self.segment_count = 0
        self.point_count = 0
        self._claims = _Claims()
        self._claimed_section = False
        self._section_count = 0
        self._state = _State.HEADER
        self.has_map = True

    @property
    def done(self) -> bool:
        return self._state is _State.DONE

    def feed(self, payload: bytes) -> bool:
        """Take one reply payload; True once the reply is complete."""
        state = self._state
        if state is _State.DONE:
            raise ReplyAlreadyComplete("getMapBinary reply already complete")
        if not payload:
            if state in (_State.SEGMENTS, _State.POINTS):
                raise PayloadError("getMapBinary reply ended inside a block of coordinates")
            self._state = _State.DONE
            return True
        if state is _State.SEGMENTS or state is _State.POINTS:
            if payload == _EMPTY_STRING and state is _State.POINTS:
                self._state = _State.AFTER_EMPTY  # lines-only server: "" instead of points
                return False
            self._block(payload, state)
            return False
        if state is _State.AFTER_EMPTY:
            raise PayloadError("getMapBinary: only the final empty packet may follow the empty string")
        if binary_block_kind(payload) is not None:
            raise PayloadError("getMapBinary: binary block outside a LINES or DATA section")
        text = _text(payload)
        if text == "":
            if state is _State.HEADER and not self.header_lines:
                self.has_map = False
                self._state = _State.DONE
                return True
            self._state = _State.AFTER_EMPTY
            return False
        section = _section(text)
        if section is not None:
            self._state = section
            self._claimed_section = text in ("LINES", "DATA")  # a scan's own section: no claim
            self._section_count = 0
            return False
        if state is not _State.HEADER:
            raise PayloadError(f"getMapBinary: unexpected text after the geometry: {text[:40]!r}")
        if len(self.header_lines) >= self.max_header_lines:
            raise MapTooLarge(f"getMapBinary: more than {self.max_header_lines} header lines")
        self._header_bytes += len(payload)
        if self._header_bytes > self.max_header_bytes:
            raise MapTooLarge(f"getMapBinary: more than {self.max_header_bytes} bytes of header")
        self.header_lines.append(text)
        self._claims.note(text)
        return False

    def _block(self, payload: bytes, state: _State) -> None:
        if state is _State.SEGMENTS:
            coords = read_block(payload, SEGMENT_BYTES, "line segment")
            n = len(coords) // SEGMENT_BYTES
            if self.segment_count + n > self.max_segments:
                raise MapTooLarge(f"getMapBinary: more than {self.max_segments} line segments")
            self.segment_count += n
            chunks = self._segment_chunks
        else:
            coords = read_block(payload, POINT_BYTES, "point")
            n = len(coords) // POINT_BYTES
            if self.point_count + n > self.max_points:
                raise MapTooLarge(f"getMapBinary: more than {self.max_points} points")
            self.point_count += n
            chunks = self._point_chunks
        self._section_count += n
        if self._claimed_section:
            claimed = self._claims.lines if state is _State.SEGMENTS else self._claims.points
            if _Claims.over(claimed, self._section_count):
                what = "line segments" if state is _State.SEGMENTS else "points"
                raise MapTooLarge(f"getMapBinary: more {what} than the map's header says ({claimed})")
        if n == 0:
            self._state = _State.BETWEEN
        else:
            chunks.append(bytes(coords))  # own the bytes even if the caller reuses a buffer

    def result(self) -> BinaryMap:
        if not self.done:
            raise PayloadError("getMapBinary reply is not complete yet")
        return BinaryMap(
            list(self.header_lines),
            _array(self._segment_chunks, 4),
            _array(self._point_chunks, 2),
            self.has_map,
        )


def _array(chunks: list[bytes], columns: int) -> np.ndarray:
    joined = bytearray().join(chunks)  # one copy, writable
    return np.frombuffer(joined, COORD_DTYPE).astype(np.int32, copy=False).reshape(-1, columns)


def map_binary_payloads(
    header_lines: Sequence[str] | None,
    segments: object = None,
    points: object = None,
    *,
    send_lines: bool = True,
    send_points: bool = True,
    per_packet: int = MAX_ITEMS_PER_PACKET,
) -> list[bytes]:
    """The ``getMapBinary`` reply payloads, as ARIA's map handler sends them.

    ``header_lines`` are the text lines before ``LINES``/``DATA`` (ARIA forces
    the first to ``2D-Map``); None means the server has no map. ``segments``
    is ``(n, 4)``, ``points`` ``(n, 2)``, in mm (floats are rounded). With
    ``send_points=False`` (a lines-only server) ``""`` replaces the points.
    """
    if header_lines is None:
        return [_EMPTY_STRING]
    if not 1 <= per_packet <= (MAX_PAYLOAD - 4) // SEGMENT_BYTES:
        raise ValueError(f"per_packet must be 1..{(MAX_PAYLOAD - 4) // SEGMENT_BYTES}")
    out = [FieldWriter().string(_checked_line(line)).bytes() for line in header_lines]
    seg = coords_bytes(segments if segments is not None else np.empty((0, 4)), 4)
    if send_lines and seg:
        out.append(FieldWriter().string("LINES").bytes())
        out.extend(_blocks(seg, SEGMENT_BYTES, per_packet))
        out.append(_BLOCK_END)
    out.append(FieldWriter().string("DATA").bytes())
    if send_points:
        pts = coords_bytes(points if points is not None else np.empty((0, 2)), 2)
        out.extend(_blocks(pts, POINT_BYTES, per_packet))
        out.append(_BLOCK_END)
    else:
        out.append(_EMPTY_STRING)
    out.append(b"")
    return out


def _blocks(coords: bytes, item_size: int, per_packet: int) -> list[bytes]:
    step = item_size * per_packet
    view = memoryview(coords)
    return [
        _COUNT.pack(len(view[i : i + step]) // item_size) + view[i : i + step].tobytes()
        for i in range(0, len(coords), step)
    ]

"""Reading maps: from a file, from text, from ``getMap`` lines, from a ``getMapBinary`` result.

Hostile input is refused before memory is spent on it: the size limit is
checked before reading, line lengths while reading, and no count written in a
header is ever used to allocate anything. The header part goes line by line
(it is short); the data part is cut into sections at its tag lines and each
section is converted in bulk (see ``numeric``).
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Mapping

import numpy as np
from numpy.typing import ArrayLike

from .errors import MapFormatError, WarningLog
from .header import HeaderReader, Section
from .model import MapData, as_rows
from .numeric import parse_rows

DEFAULT_MAX_BYTES = 512 << 20
"""Largest map accepted (a 1 M-point map is ~12 MB)."""
DEFAULT_MAX_LINE = 64 << 10
"""Longest line accepted; ARIA's own reader splits lines at 10000 characters."""
DEFAULT_MAX_HEADER_LINES = 250_000
"""Header lines (objects, info, unknown lines) are handled one by one in Python, so they are bounded too."""

_READ_CHUNK = 8 << 20
_TAG_CANDIDATE = re.compile(rb"\n[^0-9\s+\-]")
"""A data-part line that starts like a word: a section tag, or garbage that will be skipped."""


def read_map(
    path: str | os.PathLike[str],
    *,
    max_bytes: int = DEFAULT_MAX_BYTES,
    max_line: int = DEFAULT_MAX_LINE,
    max_header_lines: int = DEFAULT_MAX_HEADER_LINES,
) -> MapData:
    """Read an ARIA ``.map`` file. I/O failures are reported as MapFormatError too, naming the file."""
    source = str(path)
    guard = _LineGuard(max_line, source)
    chunks: list[bytes] = []
    try:
        with open(path, "rb") as file:
            size = os.fstat(file.fileno()).st_size
            if size > max_bytes:
                raise MapFormatError(f"file is {size} bytes, over the {max_bytes}-byte limit", source)
            total = 0
            while chunk := file.read(_READ_CHUNK):
                total += len(chunk)
                if total > max_bytes:
                    raise MapFormatError(f"file grew over the {max_bytes}-byte limit while read", source)
                guard.feed(chunk)
                chunks.append(chunk)
    except OSError as exc:
        raise MapFormatError(f"cannot read: {exc.strerror or exc}", source) from exc
    return _parse_bytes(b"".join(chunks), source, max_header_lines)


def parse_map(
    data: str | bytes,
    *,
    source: str = "<map>",
    max_bytes: int = DEFAULT_MAX_BYTES,
    max_line: int = DEFAULT_MAX_LINE,
    max_header_lines: int = DEFAULT_MAX_HEADER_LINES,
) -> MapData:
    """Parse the text of a whole map file (str is taken as latin-1 text, as ARIA has no UTF-8)."""
    raw = _latin1(data, source) if isinstance(data, str) else bytes(data)
    if len(raw) > max_bytes:
        raise MapFormatError(f"map is {len(raw)} bytes, over the {max_bytes}-byte limit", source)
    _LineGuard(max_line, source).feed_all(raw)
    return _parse_bytes(raw, source, max_header_lines)


def parse_map_lines(
    lines: Iterable[str] | Iterable[bytes],
    *,
    source: str = "<getMap>",
    max_bytes: int = DEFAULT_MAX_BYTES,
    max_line: int = DEFAULT_MAX_LINE,
    max_header_lines: int = DEFAULT_MAX_HEADER_LINES,
) -> MapData:
    """Parse a map given as lines without line ends (``getMap`` sends one per packet)."""
    items = list(lines)
    if not items:
        raise MapFormatError("no lines: the server sent no map", source)
    try:
        is_text = isinstance(items[0], str)
        raw = _latin1("\n".join(items), source) if is_text else b"\n".join(items)  # type: ignore[arg-type]
    except TypeError as exc:
        raise MapFormatError(f"lines must all be str or all bytes: {exc}", source) from None
    if raw.count(b"\n") != len(items) - 1:
        raise MapFormatError("a line contains a line break", source)
    if len(raw) > max_bytes:
        raise MapFormatError(f"map is {len(raw)} bytes, over the {max_bytes}-byte limit", source)
    _LineGuard(max_line, source).feed_all(raw)
    return _parse_bytes(raw + b"\n", source, max_header_lines)


def from_stream(
    header_lines: Iterable[str] | Iterable[bytes],
    segments: ArrayLike | None,
    points: ArrayLike | None,
    *,
    source: str = "<getMapBinary>",
    scans: Mapping[str, tuple[ArrayLike | None, ArrayLike | None]] | None = None,
    max_line: int = DEFAULT_MAX_LINE,
    max_header_lines: int = DEFAULT_MAX_HEADER_LINES,
) -> MapData:
    """A map from a ``getMapBinary``/``getMapWithMaxCategory`` reply: header text plus decoded arrays.

    ``segments``/``points`` belong to the default (unprefixed) scan; ``scans``
    maps other scan names (as in ``Sources:``) to their (segments, points).
    """
    log = WarningLog()
    reader = HeaderReader(source, log)
    for line_no, line in enumerate(header_lines, 1):
        text = line.decode("latin-1") if isinstance(line, bytes) else str(line)
        if len(text) > max_line:
            raise MapFormatError(f"line longer than {max_line} bytes", source, line_no)
        if line_no > max_header_lines:
            raise MapFormatError(f"header longer than {max_header_lines} lines", source, line_no)
        if "\n" in text:
            raise MapFormatError("a line contains a line break", source, line_no)
        if reader.feed(text.replace("\r", ""), line_no) is not None:
            break
    if not reader.got_category:
        raise MapFormatError("no map category line in the header", source)
    result = reader.map
    default = next((i for i, s in enumerate(result.scans) if s.prefix == ""), 0)
    arrays = {default: (segments, points)}
    for name, pair in (scans or {}).items():
        index = next((i for i, s in enumerate(result.scans) if s.name.lower() == name.lower()), None)
        if index is None:
            raise MapFormatError(f"data for scan {name!r}, which Sources: does not list", source)
        arrays[index] = pair
    for index, (segs, pts) in arrays.items():
        try:
            result.scans[index].segments = as_rows(segs, 4, "segments")
            result.scans[index].points = as_rows(pts, 2, "points")
        except ValueError as exc:
            raise MapFormatError(str(exc), source) from None
    _finish(result, log)
    return result


# -- internals -------------------------------------------------------------------------------------


def _latin1(text: str, source: str) -> bytes:
    try:
        return text.encode("latin-1")
    except UnicodeEncodeError as exc:
        raise MapFormatError(
            f"character {text[exc.start]!r} is not latin-1 (ARIA maps are 8-bit)", source
        ) from None


class _LineGuard:
    """Refuses a line over the limit as soon as the bytes holding it are seen."""

    def __init__(self, max_line: int, source: str) -> None:
        self.max_line = max_line
        self.source = source
        self.current = 0
        self.line = 1

    def feed(self, chunk: bytes | memoryview) -> None:
        raw = np.frombuffer(chunk, dtype=np.uint8)
        breaks = np.flatnonzero(raw == 10)
        if len(breaks) == 0:
            self.current += len(raw)
            self._check(self.current, self.line)
            return
        self._check(self.current + int(breaks[0]), self.line)
        if len(breaks) > 1:
            gaps = np.diff(breaks) - 1
            too_long = np.flatnonzero(gaps > self.max_line)
            if len(too_long):
                self._check(int(gaps[too_long[0]]), self.line + 1 + int(too_long[0]))
        self.line += len(breaks)
        self.current = len(raw) - int(breaks[-1]) - 1
        self._check(self.current, self.line)

    def feed_all(self, data: bytes) -> None:
        view = memoryview(data)
        for start in range(0, len(data), _READ_CHUNK):
            self.feed(view[start : start + _READ_CHUNK])

    def _check(self, length: int, line: int) -> None:
        if length > self.max_line:
            raise MapFormatError(f"line longer than {self.max_line} bytes", self.source, line)


def _parse_bytes(data: bytes, source: str, max_header_lines: int) -> MapData:
    if b"\r" in data:
        data = data.replace(b"\r", b"")
    log = WarningLog()
    reader = HeaderReader(source, log)
    pos = 0
    line_no = 0
    section: Section | None = None
    while pos < len(data) and section is None:
        end = data.find(b"\n", pos)
        if end < 0:
            end = len(data)
        line_no += 1
        if line_no > max_header_lines:
            raise MapFormatError(f"header longer than {max_header_lines} lines", source, line_no)
        section = reader.feed(data[pos:end].decode("latin-1"), line_no)
        pos = end + 1
    if not reader.got_category:
        raise MapFormatError("empty: no map category line", source)
    if section is None:
        raise MapFormatError("ends before any DATA or LINES section (truncated?)", source, line_no)
    _read_sections(data, pos, line_no + 1, section, reader, log)
    _finish(reader.map, log)
    return reader.map


def _read_sections(
    data: bytes, pos: int, line_no: int, section: Section, reader: HeaderReader, log: WarningLog
) -> None:
    """Everything after the first tag: cut at tag lines (matched by case-insensitive prefix), parse each."""
    tags = reader.data_tags()
    longest = max(len(tag) for tag, _ in tags)
    pieces: dict[Section, list[np.ndarray]] = {}

    def parse(start: int, end: int, first_line: int, current: Section) -> None:
        if end > start:
            width = 4 if current.is_lines else 2
            pieces.setdefault(current, []).append(parse_rows(data[start:end], width, first_line, log))

    body_start = pos
    counted_to = pos
    for match in _TAG_CANDIDATE.finditer(data, max(pos - 1, 0)):
        line_start = match.start() + 1
        head = data[line_start : line_start + longest].lower()
        found = next((s for tag, s in tags if head.startswith(tag)), None)
        if found is None:
            continue  # garbage: stays in the body and is skipped there with a warning
        parse(body_start, line_start, line_no, section)
        line_no += data.count(b"\n", counted_to, line_start) + 1
        end = data.find(b"\n", line_start)
        body_start = counted_to = len(data) if end < 0 else end + 1
        section = found
    parse(body_start, len(data), line_no, section)
    for (scan_index, is_lines), parts in pieces.items():
        scan = reader.map.scans[scan_index]
        merged = parts[0] if len(parts) == 1 else np.concatenate(parts)
        if is_lines:
            scan.segments = merged
        else:
            scan.points = merged


def _finish(result: MapData, log: WarningLog) -> None:
    result.skipped_lines = log.skipped_lines
    result.warnings = sorted(log.kept)
    result.warning_count = log.count

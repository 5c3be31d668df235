"""Writing maps in ARIA's order (category, sources, per-scan header, georeference, info, objects, inactive and
kept lines, then every ``LINES`` section, then every ``DATA`` section), with counts and boxes recomputed."""

from __future__ import annotations

import os
import secrets
from pathlib import Path

from .model import CATEGORIES, INFO_KEYWORDS, MapData, MapObject, MapScan, as_rows, map_category, rows_bounds
from .numeric import format_rows
from .tokens import SPACE, format_heading, format_number, split_keyword, split_tokens


def map_header_lines(data: MapData) -> list[str]:
    """Every line before the data sections."""
    category = map_category(data.category)
    if category is None:
        raise ValueError(f"unknown map category {data.category!r}; use one of {', '.join(CATEGORIES)}")
    lines = [category]
    names = [scan.name for scan in data.scans]
    if any(names):
        if not all(names) or any(_has_space(n) for n in names):
            raise ValueError(f"with named scans every scan needs a one-word name, got {names}")
        lines.append("Sources: " + " ".join(names))
    for scan in data.scans:
        lines.extend(_scan_header(scan))
    if data.origin_lat_long_alt is not None:
        lat, lon, alt = data.origin_lat_long_alt
        lines.append(f"OriginLatLongAlt: {lat:f} {lon:f} {alt:f}")
    lines.extend(_info_lines(data, ""))
    lines.extend("Cairn: " + object_text(obj) for obj in data.objects)
    lines.extend(_info_lines(data, "_"))
    lines.extend(_checked(f"_Cairn: {args}") for args in data.inactive_objects)
    lines.extend(_checked(f"ChildCairn: {args}") for args in data.child_objects)
    lines.extend(_unknown(line, data) for line in data.unknown_lines)
    return lines


def object_text(obj: MapObject) -> str:
    """A map object as ARIA writes it after ``Cairn:`` (whole-mm positions, heading with six decimals)."""
    for label, value in (("type", obj.type), ("icon", obj.icon)):
        if not value or _has_space(value) or '"' in value:
            raise ValueError(f"map object {label} must be one word, got {value!r}")
    for label, value in (("name", obj.name), ("description", obj.description)):
        # A quote inside is fine as long as the quoted text still reads back as one token.
        if "\n" in value or "\r" in value or split_tokens(f'"{value}"') != [f'"{value}"']:
            raise ValueError(f"map object {label} cannot be quoted and read back: {value!r}")
    text = (
        f"{obj.type} {format_number(obj.x)} {format_number(obj.y)} {format_heading(obj.th)}"
        f' "{obj.description}" {obj.icon} "{obj.name}"'
    )
    if obj.from_xy is not None and obj.to_xy is not None:
        text += " " + " ".join(format_number(v) for v in (*obj.from_xy, *obj.to_xy))
    return text


def map_bytes(data: MapData) -> bytes:
    """The whole file: latin-1, ``\\n`` after every line."""
    try:
        head = ("\n".join(map_header_lines(data)) + "\n").encode("latin-1")
    except UnicodeEncodeError as exc:
        raise ValueError(f"map text holds {exc.object[exc.start]!r}, which is not latin-1") from None
    parts = [head]
    for scan in data.scans:
        segments = as_rows(scan.segments, 4, "segments")
        if len(segments):
            parts.append(scan.lines_tag.encode("latin-1") + b"\n")
            parts.append(format_rows(segments))
    for scan in data.scans:
        parts.append(scan.points_tag.encode("latin-1") + b"\n")
        parts.append(format_rows(as_rows(scan.points, 2, "points")))
    return b"".join(parts)


def map_lines(data: MapData) -> list[str]:
    """The whole file as lines without line ends."""
    return map_bytes(data).decode("latin-1").split("\n")[:-1]


def write_map(data: MapData, path: str | os.PathLike[str]) -> None:
    """Write ``data`` to ``path``, replacing it atomically (a reader never sees half a map)."""
    payload = map_bytes(data)
    target = Path(path)
    # A temporary file beside the target, created with open() so the usual umask applies.
    temp = target.with_name(f".{target.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp")
    try:
        with open(temp, "xb") as file:
            file.write(payload)
        os.replace(temp, target)
    except BaseException:
        temp.unlink(missing_ok=True)
        raise


def _scan_header(scan: MapScan) -> list[str]:
    p = scan.prefix
    lines = []
    if scan.display is not None:
        lines.append(_checked(f'{p}Display: "{scan.display}"'))
    points = as_rows(scan.points, 2, "points")
    box = rows_bounds(points)
    if box is not None:
        lines += [
            f"{p}MinPos: {box.min_x} {box.min_y}",
            f"{p}MaxPos: {box.max_x} {box.max_y}",
            f"{p}NumPoints: {len(points)}",
            f"{p}PointsAreSorted: {'true' if scan.points_sorted else 'false'}",
        ]
    if scan.resolution is not None:
        lines.append(f"{p}Resolution: {int(scan.resolution)}")
    segments = as_rows(scan.segments, 4, "segments")
    box = rows_bounds(segments)
    if box is not None:
        lines += [
            f"{p}LineMinPos: {box.min_x} {box.min_y}",
            f"{p}LineMaxPos: {box.max_x} {box.max_y}",
            f"{p}NumLines: {len(segments)}",
            f"{p}LinesAreSorted: {'true' if scan.lines_sorted else 'false'}",
        ]
    return lines


def _info_lines(data: MapData, prefix: str) -> list[str]:
    lines = []
    for keyword in INFO_KEYWORDS:
        wanted = prefix + keyword
        for info in data.info:
            if info.keyword == wanted:
                lines.append(_checked(f"{wanted}: {info.args}" if info.args else f"{wanted}:"))
    known = {prefix + k for k in INFO_KEYWORDS for prefix in ("", "_")}
    strays = [info.keyword for info in data.info if info.keyword not in known]
    if strays and prefix == "":
        raise ValueError(f"unknown info keyword(s) {strays}; keep such lines in unknown_lines")
    return lines


def _unknown(line: str, data: MapData) -> str:
    """A kept line, unless written back it would read as something else (blank, or a data tag)."""
    keyword = split_keyword(_checked(line))[0].lower()
    tags = {tag.lower() for scan in data.scans for tag in (scan.points_tag, scan.lines_tag)}
    if not keyword or keyword in tags:
        raise ValueError(f"{line!r} cannot be kept as an unknown header line")
    return line


def _checked(line: str) -> str:
    if "\n" in line or "\r" in line:
        raise ValueError(f"a map line cannot hold a line break: {line[:40]!r}")
    return line


def _has_space(text: str) -> bool:
    return any(ch in SPACE for ch in text)

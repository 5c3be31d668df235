"""The header part of a map, one line at a time: category, keywords, objects, kept lines, up to a data tag.

Shared by the file reader, by ``getMap`` lines and by ``getMapBinary``'s text
part. Keywords are the first token, matched case-insensitively; a known keyword
with unusable arguments is an error (ARIA refuses such a map too); an unknown
one is kept verbatim.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import ClassVar, NamedTuple, NoReturn

from .errors import MapFormatError, WarningLog
from .model import (
    CATEGORIES,
    INFO_KEYWORDS,
    LINE_TYPES,
    RECTANGLE_TYPES,
    InfoLine,
    MapData,
    MapObject,
    MapScan,
    map_category,
)
from .tokens import (
    SPACE,
    TokenError,
    parse_float,
    split_keyword,
    split_tokens,
    split_words,
    unquote,
)

_INFO_BY_LOWER = {f"{k.lower()}:": k for k in INFO_KEYWORDS} | {
    f"_{k.lower()}:": f"_{k}" for k in INFO_KEYWORDS
}
_SCAN_KEYWORDS = {
    name.lower(): name
    for name in (
        "Display",
        "MinPos",
        "MaxPos",
        "NumPoints",
        "PointsAreSorted",
        "Resolution",
        "LineMinPos",
        "LineMaxPos",
        "NumLines",
        "LinesAreSorted",
    )
}

_CLAIM_FIELDS = {
    "minpos": "min_pos",
    "maxpos": "max_pos",
    "lineminpos": "line_min_pos",
    "linemaxpos": "line_max_pos",
}


class Section(NamedTuple):
    """Which data a tag starts: the scan (index into ``MapData.scans``) and points or segments."""

    scan: int
    is_lines: bool


class HeaderReader:
    """Feeds header lines into a fresh MapData; ``feed`` returns a Section when the line is a data tag."""

    def __init__(self, source: str, log: WarningLog) -> None:
        self.map = MapData(source=source)
        self.log = log
        self.got_category = False
        self._sources_seen = False
        self._scan_keywords: dict[str, tuple[int, str]] = {}
        self._tags: dict[str, Section] = {}
        self._boundary_types = set(LINE_TYPES) | set(RECTANGLE_TYPES)
        self._index_scans()

    # -- public -------------------------------------------------------------------------------------

    def feed(self, line: str, line_no: int) -> Section | None:
        keyword, args = split_keyword(line)
        if not keyword:
            return None  # blank lines are ignored
        if not self.got_category:
            self._category(keyword, args, line_no)
            return None
        lower = keyword.lower()
        tag = self._tags.get(lower)
        if tag is not None:
            return tag
        try:
            self._keyword(line, lower, args, line_no)
        except TokenError as exc:
            raise MapFormatError(f"{keyword} {exc}", self.map.source, line_no) from None
        return None

    def data_tags(self) -> list[tuple[bytes, Section]]:
        """Tags that start a data section, lower-case, longest first (a data line matches them by prefix)."""
        tags = []
        for index, scan in enumerate(self.map.scans):
            tags.append((scan.points_tag.encode("latin-1").lower(), Section(index, False)))
            tags.append((scan.lines_tag.encode("latin-1").lower(), Section(index, True)))
        return sorted(tags, key=lambda item: -len(item[0]))

    # -- category and keywords ----------------------------------------------------------------------

    def _category(self, keyword: str, args: str, line_no: int) -> None:
        category = map_category(keyword)
        if category is None:
            shown = f"{keyword} {args}".strip(SPACE)[:40]
            raise MapFormatError(
                f"not an ARIA map: first line is {shown!r}, expected one of {', '.join(CATEGORIES)}"
                " (or a later 2D-Map-ExN)",
                self.map.source,
                line_no,
            )
        if args:
            self.log.add(line_no, f"text after the map category ignored: {args[:40]!r}")
        self.map.category = category
        self.got_category = True

    def _keyword(self, line: str, lower: str, args: str, line_no: int) -> None:
        scan_field = self._scan_keywords.get(lower)
        if scan_field is not None:
            self._scan_field(scan_field[0], scan_field[1], args, line_no)
            return
        handler = self._HANDLERS.get(lower)
        if handler is not None:
            handler(self, args, line_no)
            return
        info = _INFO_BY_LOWER.get(lower)
        if info is not None:
            if info == "MapInfo":
                self._note_boundary_type(args)
            self.map.info.append(InfoLine(info, args))
            return
        self.map.unknown_lines.append(line)

    def _sources(self, args: str, line_no: int) -> None:
        if self._sources_seen:
            raise MapFormatError("a second Sources: line", self.map.source, line_no)
        names = [unquote(t) for t in split_tokens(args)]
        if not names:
            return
        if len({n.lower() for n in names}) != len(names):
            raise MapFormatError(f"Sources: names a scan twice: {args[:60]!r}", self.map.source, line_no)
        self._sources_seen = True
        old_default = self.map.scans[0]
        scans = [MapScan(name=name) for name in names]
        for scan in scans:
            if scan.prefix == "":
                # Keywords of the default scan read before Sources: belong to the unprefixed scan.
                old_default.name = scan.name
                scans[scans.index(scan)] = old_default
                break
        self.map.scans = scans
        self._index_scans()

    def _origin(self, args: str, line_no: int) -> None:
        values = [parse_float(t) for t in split_words(args)]
        if len(values) != 3 or any(v is None for v in values):
            self._bad("OriginLatLongAlt: needs three numbers (latitude longitude altitude)", args, line_no)
        lat, lon, alt = (float(v) for v in values if v is not None)
        self.map.origin_lat_long_alt = (lat, lon, alt)

    def _cairn(self, args: str, line_no: int) -> None:
        self.map.objects.append(self._map_object(args, line_no))

    def _inactive_cairn(self, args: str, line_no: int) -> None:
        self.map.inactive_objects.append(args)

    def _child_cairn(self, args: str, line_no: int) -> None:
        self.map.child_objects.append(args)

    _HANDLERS: ClassVar[dict[str, Callable[[HeaderReader, str, int], None]]] = {
        "sources:": _sources,
        "originlatlongalt:": _origin,
        "cairn:": _cairn,
        "_cairn:": _inactive_cairn,
        "childcairn:": _child_cairn,
    }

    # -- scans --------------------------------------------------------------------------------------

    def _index_scans(self) -> None:
        self._scan_keywords = {}
        self._tags = {}
        for index, scan in enumerate(self.map.scans):
            prefix = scan.prefix.lower()
            for name in _SCAN_KEYWORDS:
                self._scan_keywords[f"{prefix}{name}:"] = (index, name)
            self._tags[scan.points_tag.lower()] = Section(index, False)
            self._tags[scan.lines_tag.lower()] = Section(index, True)

    def _scan_field(self, index: int, name: str, args: str, line_no: int) -> None:
        scan = self.map.scans[index]
        claims = scan.claimed
        keyword = f"{scan.prefix}{_SCAN_KEYWORDS[name]}:"
        tokens = split_words(args)
        if name == "display":
            scan.display = unquote(args)
        elif name in ("minpos", "maxpos", "lineminpos", "linemaxpos"):
            values = [parse_float(t) for t in tokens]
            if len(values) != 2 or values[0] is None or values[1] is None:
                self._bad(f"{keyword} needs two numbers (x y)", args, line_no)
            x, y = (round(v) for v in values if v is not None)
            setattr(claims, _CLAIM_FIELDS[name], (x, y))
        elif name in ("numpoints", "numlines", "resolution"):
            number = parse_float(tokens[0]) if len(tokens) == 1 else None
            if number is None or not number.is_integer() or (number < 0 and name != "resolution"):
                self._bad(f"{keyword} needs one whole number", args, line_no)
            value = int(number)
            if name == "resolution":
                scan.resolution = None if value < 0 else value
            elif name == "numpoints":
                claims.num_points = value
            else:
                claims.num_lines = value
        else:  # pointsaresorted, linesaresorted
            flag = tokens[0].lower() if len(tokens) == 1 else ""
            if flag not in ("true", "false", "1", "0"):
                self._bad(f"{keyword} needs true or false", args, line_no)
            setattr(
                scan, "points_sorted" if name == "pointsaresorted" else "lines_sorted", flag in ("true", "1")
            )

    # -- objects ------------------------------------------------------------------------------------

    def _note_boundary_type(self, args: str) -> None:
        """Remember custom line/rectangle types so their Cairn lines are checked for end points."""
        tokens = split_words(args)
        if not tokens or tokens[0] not in ("BoundaryType", "SectorType"):
            return
        try:
            tokens = split_tokens(args)
        except TokenError:
            return  # the line is kept verbatim anyway; only the end-point check is lost
        for token in tokens[1:]:
            key, _, value = unquote(token).partition("=")
            if key == "Name" and value:
                self._boundary_types.add(value.lower())

    def _map_object(self, args: str, line_no: int) -> MapObject:
        tokens = split_tokens(args)
        if len(tokens) < 7:
            self._bad(
                f'Cairn: needs at least 7 fields (type x y th "description" icon "name"), got {len(tokens)}',
                args,
                line_no,
            )
        kind = tokens[0]
        pose = [parse_float(t) for t in tokens[1:4]]
        if any(v is None for v in pose):
            self._bad("Cairn: x y th must be numbers", args, line_no)
        x, y, th = (float(v) for v in pose if v is not None)
        description = unquote(tokens[4])
        icon = tokens[5]
        name = unquote(tokens[6])
        from_xy = to_xy = None
        if len(tokens) >= 11:
            ends = [parse_float(t) for t in tokens[7:11]]
            if any(v is None for v in ends):
                self._bad("Cairn: x1 y1 x2 y2 must be numbers", args, line_no)
            x1, y1, x2, y2 = (float(v) for v in ends if v is not None)
            from_xy, to_xy = (x1, y1), (x2, y2)
            extra_at = 11
        else:
            if kind.lower() in self._boundary_types:
                self._bad(f"Cairn: {kind} needs its end points x1 y1 x2 y2", args, line_no)
            extra_at = 7
        if len(tokens) > extra_at:
            # ARIA reads a description here (an older layout); anything after it is ignored.
            description = unquote(tokens[extra_at])
            if len(tokens) > extra_at + 1:
                self.log.add(
                    line_no, f"Cairn: extra fields ignored: {' '.join(tokens[extra_at + 1 :])[:40]!r}"
                )
        return MapObject(kind, x, y, th, description, icon, name, from_xy, to_xy)

    def _bad(self, message: str, args: str, line_no: int) -> NoReturn:
        raise MapFormatError(f"{message}: {args[:60]!r}", self.map.source, line_no)

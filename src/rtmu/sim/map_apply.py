"""Applying a ``processMapChanges`` change set to a map, the way ARIA's ``ArMapChanger`` does.

All or nothing: the changes are made on a copy, and any that cannot be made refuses the whole set
(:class:`ChangeRefused`, in words for the log; ARIA's reply itself carries no words).

* Objects: each deleted ``Cairn:`` line removes the first object it matches — by name (ignoring case)
  when it has one, else by type, pose, end points, description and icon; one that matches nothing
  refuses the set. Added objects go to the end of the list.
* Points and segments: a deletion removes one equal item per deleted item (deleting at least as many
  as there are replaces them all with the additions); points end up sorted, as ARIA sorts them.
* Info lines (``MapInfo:`` …, chosen by their index in ARIA's list): deleted lines that match go,
  added ones are put after the section's other lines. Summary lines (counts, bounds) are recomputed
  anyway; a supplement line may set ``OriginLatLongAlt:``.
* Then the ids of the set's start packet are checked against the result: a checksum must be the new
  map's MD5, and a non-null new id must equal the new map's id (size, time, checksum, names).
"""

from __future__ import annotations

import copy
import hashlib
import re
from collections import defaultdict, deque
from collections.abc import Sequence

import numpy as np

from rtmu.mapfile import (
    InfoLine,
    MapData,
    MapFormatError,
    MapObject,
    map_bytes,
    map_header_lines,
    parse_map_lines,
    split_keyword,
)
from rtmu.protocol.payloads.map import MapId
from rtmu.protocol.payloads.mapchange import INFO_NAMES, ChangeData, LineChange, MapChangeSet


class ChangeRefused(Exception):
    """The change set cannot be applied; the map stays as it was."""


def apply_changes(data: MapData, changes: MapChangeSet) -> MapData:
    """A new map: ``data`` with ``changes`` applied (``data`` itself is left alone)."""
    out = copy.copy(data)
    out.scans = [copy.copy(s) for s in data.scans]
    out.objects = _objects(data.objects, changes)
    out.info = _info(data.info, changes)
    for s in changes.line_sets:
        if s.data is ChangeData.SUPPLEMENT and s.change is LineChange.ADDITIONS:
            for g in s.groups:
                out.origin_lat_long_alt = _origin(g.parent.text)
    scans = {c.scan_type for c in changes.coord_sets}
    for scan_type in scans:
        scan = next(
            (s for s in out.scans if s.name == scan_type or (not scan_type and s is out.scans[0])), None
        )
        if scan is None:
            raise ChangeRefused(f"the map has no scan {scan_type!r}")
        pts = _coords(scan.points, changes, ChangeData.POINTS, scan_type)
        scan.points = pts[np.lexsort((pts[:, 1], pts[:, 0]))] if len(pts) else pts
        scan.points_sorted = True
        scan.segments = _coords(scan.segments, changes, ChangeData.LINES, scan_type)
    return out


def check_ids(changes: MapChangeSet, result: bytes, name: str, mtime: int) -> None:
    """ARIA's checks of the start packet's new id against the map it would write."""
    wanted = changes.new_id
    md5 = hashlib.md5(result).digest()
    if wanted.checksum and wanted.checksum != md5:
        raise ChangeRefused("the map's checksum after the change is not the one the client sent")
    if wanted.is_null:
        return
    made = MapId("", name, md5, len(result), mtime)
    if not same_id(wanted, made):
        raise ChangeRefused("the map written is not the one the client's new map id describes")


def same_id(a: MapId, b: MapId) -> bool:
    """ARIA's ``operator==`` of map ids: a timestamp of -1 or 0 matches any other."""
    if a.size != b.size or len(a.checksum) != len(b.checksum) or a.checksum != b.checksum:
        return False
    if a.mtime not in (-1, 0) and b.mtime not in (-1, 0) and a.mtime != b.mtime:
        return False
    return a.source_name.lower() == b.source_name.lower() and a.file_name.lower() == b.file_name.lower()


def same_file(this: MapId, other: MapId) -> bool:
    """ARIA's ``isSameFile``: name (ignoring case), size and checksum."""
    if this.file_name.lower() != other.file_name.lower() or this.size != other.size:
        return False
    if len(this.checksum) != len(other.checksum):
        return False
    return not (this.checksum and other.checksum and this.checksum != other.checksum)


def result_bytes(
    changed: MapData, before: MapData | None = None, before_raw: bytes = b""
) -> tuple[bytes, list[str]]:
    """The changed map's file and its header lines (as ARIA writes the file after a change).

    When the change left every scan's points and segments as they were, the data sections of
    ``before_raw`` are kept byte for byte after the new header: a 1 M-point map's points are not
    formatted again for a goal added.
    """
    header = map_header_lines(changed)
    try:
        head = ("\n".join(header) + "\n").encode("latin-1")
    except UnicodeEncodeError as exc:
        raise ChangeRefused(
            f"the changed map holds text that is not latin-1: {exc.object[exc.start]!r}"
        ) from None
    if before is not None and same_geometry(before, changed):
        tail = _data_part(before_raw, changed)
        if tail is not None:
            return head + tail, header
    return map_bytes(changed), header


def same_geometry(a: MapData, b: MapData) -> bool:
    """Whether ``b`` still holds ``a``'s very point and segment arrays (a change of objects only)."""
    return len(a.scans) == len(b.scans) and all(
        x.points is y.points and x.segments is y.segments for x, y in zip(a.scans, b.scans, strict=True)
    )


def _data_part(raw: bytes, data: MapData) -> bytes | None:
    """``raw`` from its first data tag line (``LINES``, ``DATA``, ``<scan>_DATA`` …) on; None without one."""
    tags = sorted({t for s in data.scans for t in (s.lines_tag, s.points_tag)})
    pattern = rb"(?m)^(?:" + b"|".join(re.escape(t.encode("latin-1")) for t in tags) + rb")\r?$"
    found = re.search(pattern, raw)
    return None if found is None else raw[found.start() :]


# -- objects ---------------------------------------------------------------------------------------


def parse_objects(lines: Sequence[str]) -> list[MapObject]:
    """``Cairn:`` lines as map objects (ChangeRefused naming the first that is not one)."""
    for text in lines:
        keyword, _ = split_keyword(text)
        if keyword.lower() != "cairn:":
            raise ChangeRefused(f"not a map object line: {text[:60]!r}")
    if not lines:
        return []
    try:
        parsed = parse_map_lines(["2D-Map", *lines, "DATA"], source="<processMapChanges>")
    except MapFormatError as exc:
        raise ChangeRefused(f"an object line does not read: {exc}") from None
    if len(parsed.objects) != len(lines):
        raise ChangeRefused("an object line does not read as one map object")
    return parsed.objects


def matching_key(obj: MapObject) -> tuple[object, ...]:
    """How ARIA tells which object a deleted line means (``isMatchingObjects``)."""
    if obj.name:
        return ("name", obj.name.lower())
    return (
        "shape", obj.type.lower(), obj.x, obj.y, obj.th, obj.from_xy, obj.to_xy,
        obj.description.lower(), obj.icon.lower(),
    )  # fmt: skip


def _objects(objects: Sequence[MapObject], changes: MapChangeSet) -> list[MapObject]:
    deleted = parse_objects(changes.lines(ChangeData.OBJECTS, LineChange.DELETIONS))
    added = parse_objects(changes.lines(ChangeData.OBJECTS, LineChange.ADDITIONS))
    where: dict[tuple[object, ...], deque[int]] = defaultdict(deque)
    for i, obj in enumerate(objects):
        where[matching_key(obj)].append(i)
    gone: set[int] = set()
    for obj in deleted:
        queue = where.get(matching_key(obj))
        if not queue:
            raise ChangeRefused(f"no object on the map matches the deleted {obj.type} {obj.name!r}")
        gone.add(queue.popleft())
    return [o for i, o in enumerate(objects) if i not in gone] + added


# -- info, supplement ------------------------------------------------------------------------------


def _info(info: Sequence[InfoLine], changes: MapChangeSet) -> list[InfoLine]:
    out = list(info)
    for change in (LineChange.DELETIONS, LineChange.ADDITIONS):
        for s in changes.line_sets:
            if s.data is not ChangeData.INFO or s.change is not change:
                continue
            if not 0 <= s.info_index < len(INFO_NAMES):
                raise ChangeRefused(f"info index {s.info_index} names no info section")
            keyword = INFO_NAMES[s.info_index][:-1]
            for g in s.groups:
                lines = [g.parent.text, *(c.text for c in g.children)]
                for text in lines:
                    word, args = split_keyword(text)
                    if word.rstrip(":").lower() != keyword.lower():
                        raise ChangeRefused(f"a {keyword} change holds another line: {text[:60]!r}")
                    line = InfoLine(keyword, args)
                    if change is LineChange.DELETIONS:
                        if line in out:
                            out.remove(line)
                    else:
                        last = max(
                            (i for i, x in enumerate(out) if x.keyword == keyword), default=len(out) - 1
                        )
                        out.insert(last + 1, line)
    return out


def _origin(text: str) -> tuple[float, float, float]:
    word, args = split_keyword(text)
    parts = args.split()
    if word.lower() != "originlatlongalt:" or len(parts) != 3:
        raise ChangeRefused(f"the simulator takes no supplement line but OriginLatLongAlt: ({text[:60]!r})")
    try:
        lat, lon, alt = (float(p) for p in parts)
    except ValueError:
        raise ChangeRefused(f"OriginLatLongAlt: wants three numbers, not {args[:60]!r}") from None
    return lat, lon, alt


# -- points and segments ---------------------------------------------------------------------------


def _coords(current: np.ndarray, changes: MapChangeSet, data: ChangeData, scan_type: str) -> np.ndarray:
    deleted = changes.coords(data, LineChange.DELETIONS, scan_type)
    added = changes.coords(data, LineChange.ADDITIONS, scan_type)
    if len(deleted) >= len(current) and len(deleted):
        return np.ascontiguousarray(added, dtype=np.int32)
    kept = _multiset_difference(current, deleted) if len(deleted) else current
    return np.ascontiguousarray(np.concatenate([kept, added]) if len(added) else kept, dtype=np.int32)


def _multiset_difference(rows: np.ndarray, remove: np.ndarray) -> np.ndarray:
    """``rows`` without one equal row per row of ``remove`` (order of the others kept)."""
    view = np.dtype((np.void, rows.dtype.itemsize * rows.shape[1]))
    keys = np.ascontiguousarray(rows).view(view).ravel()
    gone_keys, gone_counts = np.unique(
        np.ascontiguousarray(remove, dtype=rows.dtype).view(view).ravel(), return_counts=True
    )
    order = np.argsort(keys, kind="stable")
    ranked = keys[order]
    rank = np.arange(len(ranked)) - np.searchsorted(ranked, ranked, side="left")
    at = np.searchsorted(gone_keys, ranked)
    at = np.minimum(at, max(len(gone_keys) - 1, 0))
    allowed = (
        np.where(gone_keys[at] == ranked, gone_counts[at], 0)
        if len(gone_keys)
        else np.zeros(len(ranked), int)
    )
    keep = np.ones(len(rows), dtype=bool)
    keep[order[rank < allowed]] = False
    return rows[keep]

"""What a map is once read: scans of points and segments (numpy int32, mm), map objects, and kept text.

The data is the truth and the header's counts and bounding boxes are claims
(ARIA recomputes them, and old files carry stale ones), so both are exposed:
``num_points`` is what was found, ``claimed.num_points`` what the header said.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from .errors import MapWarning

CATEGORIES = ("2D-Map", "2D-Map-Ex", "2D-Map-Ex2", "2D-Map-Ex3", "2D-Map-Ex4")
"""The known first lines, in ARIA's spelling (matched case-insensitively). Later ``2D-Map-ExN`` are
accepted too (see :func:`map_category`): each new ARIA/ARAM generation only adds header lines, which
are kept verbatim, so refusing an unknown N would lose whole maps for nothing."""

_LATER_EX = re.compile(r"2D-Map-Ex([1-9][0-9]{0,3})", re.IGNORECASE)
_CATEGORY_BY_LOWER = {c.lower(): c for c in CATEGORIES}


def map_category(word: str) -> str | None:
    """The category named by a map's first word in ARIA's spelling, or None when it is not a map."""
    known = _CATEGORY_BY_LOWER.get(word.lower())
    if known is not None:
        return known
    match = _LATER_EX.fullmatch(word)
    return f"2D-Map-Ex{int(match.group(1))}" if match else None


INFO_KEYWORDS = (
    "MapInfo",
    "MetaInfo",
    "TaskInfo",
    "RouteInfo",
    "SchedTaskInfo",
    "SchedInfo",
    "CairnInfo",
    "CustomInfo",
)
"""Info sections kept verbatim, in writer order; each also exists inactive with a ``_`` prefix."""

GOAL_TYPES = ("goal", "goalwithheading")
LINE_TYPES = ("forbiddenline",)
RECTANGLE_TYPES = ("forbiddenarea",)

_INT32 = np.iinfo(np.int32)


class Pose(NamedTuple):
    x: float
    y: float
    th: float


class Bounds(NamedTuple):
    """Axis-aligned box in mm, inclusive."""

    min_x: int
    min_y: int
    max_x: int
    max_y: int

    def union(self, other: Bounds | None) -> Bounds:
        if other is None:
            return self
        return Bounds(
            min(self.min_x, other.min_x),
            min(self.min_y, other.min_y),
            max(self.max_x, other.max_x),
            max(self.max_y, other.max_y),
        )


class InfoLine(NamedTuple):
    """A ``MapInfo:``/``MetaInfo:``/… line: keyword without colon (``_MapInfo`` if inactive), raw args."""

    keyword: str
    args: str


@dataclass(frozen=True)
class MapObject:
    """A ``Cairn:`` line: a goal, home, dock, forbidden line/area or a custom type.

    ``x``/``y``/``th`` are the pose (mm, degrees). Line and rectangle types also
    carry ``from_xy``/``to_xy`` (the line's ends, or two opposite corners of a
    rectangle that ARIA rotates by ``th`` about the map origin).
    """

    type: str
    x: float
    y: float
    th: float = 0.0
    description: str = ""
    icon: str = "ICON"
    name: str = ""
    from_xy: tuple[float, float] | None = None
    to_xy: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        if (self.from_xy is None) != (self.to_xy is None):
            raise ValueError("from_xy and to_xy go together")

    @property
    def pose(self) -> Pose:
        return Pose(self.x, self.y, self.th)

    @property
    def has_from_to(self) -> bool:
        return self.from_xy is not None

    @property
    def base_type(self) -> str:
        """The type without a ``WithHeading`` suffix (how ARIA groups ``GoalWithHeading`` with ``Goal``)."""
        if not self.has_from_to and self.type.endswith("WithHeading") and len(self.type) > 11:
            return self.type[: -len("WithHeading")]
        return self.type

    @property
    def is_goal(self) -> bool:
        """Listed by ``getGoals``: type ``Goal`` or ``GoalWithHeading``, any case."""
        return self.type.lower() in GOAL_TYPES


def empty_points() -> np.ndarray:
    return np.zeros((0, 2), dtype=np.int32)


def empty_segments() -> np.ndarray:
    return np.zeros((0, 4), dtype=np.int32)


def as_rows(values: ArrayLike | None, width: int, what: str) -> np.ndarray:
    """``values`` as a C-contiguous int32 array of shape (n, width); floats are rounded; range checked."""
    if values is None:
        return np.zeros((0, width), dtype=np.int32)
    array = np.asarray(values)
    if array.dtype == np.int32 and array.ndim == 2 and array.shape[1] == width:
        return np.ascontiguousarray(array)
    if array.size == 0:
        return np.zeros((0, width), dtype=np.int32)
    if array.ndim != 2 or array.shape[1] != width:
        raise ValueError(f"{what} must have shape (n, {width}), not {array.shape}")
    if array.dtype.kind == "f":
        if not np.isfinite(array).all():
            raise ValueError(f"{what} contain a non-finite value")
        array = np.rint(array)
    elif array.dtype.kind not in "iu":
        raise ValueError(f"{what} must be numbers, not {array.dtype}")
    if array.min() < _INT32.min or array.max() > _INT32.max:
        raise ValueError(f"{what} exceed the 32-bit range of map coordinates")
    return np.ascontiguousarray(array, dtype=np.int32)


def rows_bounds(rows: np.ndarray) -> Bounds | None:
    """Bounding box of points (n, 2) or of both ends of segments (n, 4); None when empty."""
    if len(rows) == 0:
        return None
    xs = rows[:, 0::2]
    ys = rows[:, 1::2]
    return Bounds(int(xs.min()), int(ys.min()), int(xs.max()), int(ys.max()))


@dataclass
class ScanClaims:
    """What the header said about a scan; None where it said nothing. Never trusted, only reported."""

    num_points: int | None = None
    num_lines: int | None = None
    min_pos: tuple[int, int] | None = None
    max_pos: tuple[int, int] | None = None
    line_min_pos: tuple[int, int] | None = None
    line_max_pos: tuple[int, int] | None = None

    @property
    def point_bounds(self) -> Bounds | None:
        if self.min_pos is None or self.max_pos is None:
            return None
        return Bounds(*self.min_pos, *self.max_pos)

    @property
    def line_bounds(self) -> Bounds | None:
        if self.line_min_pos is None or self.line_max_pos is None:
            return None
        return Bounds(*self.line_min_pos, *self.line_max_pos)


@dataclass(eq=False)
class MapScan:
    """One sensor's data. ``name`` is from ``Sources:``; "" (or ``SickLaser``) uses unprefixed keywords."""

    name: str = ""
    points: np.ndarray = field(default_factory=empty_points)
    segments: np.ndarray = field(default_factory=empty_segments)
    display: str | None = None
    resolution: int | None = None
    points_sorted: bool = False
    lines_sorted: bool = False
    claimed: ScanClaims = field(default_factory=ScanClaims)

    def __post_init__(self) -> None:
        self.points = as_rows(self.points, 2, "points")
        self.segments = as_rows(self.segments, 4, "segments")

    @property
    def prefix(self) -> str:
        """Keyword prefix: none for the default scan and for ``SickLaser``, else the scan name."""
        return "" if self.name.lower() in ("", "sicklaser") else self.name

    @property
    def points_tag(self) -> str:
        return f"{self.prefix}_DATA" if self.prefix else "DATA"

    @property
    def lines_tag(self) -> str:
        return f"{self.prefix}_LINES" if self.prefix else "LINES"

    def point_bounds(self) -> Bounds | None:
        return rows_bounds(self.points)

    def line_bounds(self) -> Bounds | None:
        return rows_bounds(self.segments)

    def __eq__(self, other: object) -> bool:
        """Same content. The header's claims are not content (a rewrite corrects them), nor is a sorted
        flag without data (the file has no place for it)."""
        if not isinstance(other, MapScan):
            return NotImplemented
        return (
            self.name == other.name
            and self.display == other.display
            and self.resolution == other.resolution
            and (len(self.points) == 0 or self.points_sorted == other.points_sorted)
            and (len(self.segments) == 0 or self.lines_sorted == other.lines_sorted)
            and np.array_equal(self.points, other.points)
            and np.array_equal(self.segments, other.segments)
        )


@dataclass(eq=False)
class MapData:
    """A whole map. The first scan is the default one; ``points``/``segments`` are its data.

    ``info`` keeps ``MapInfo:``/``MetaInfo:``/… lines (and their inactive ``_``
    forms) in file order; ``inactive_objects``/``child_objects`` keep the
    arguments of ``_Cairn:``/``ChildCairn:`` lines verbatim; ``unknown_lines``
    keeps every other header line exactly as read, to be written back.
    """

    category: str = "2D-Map"
    scans: list[MapScan] = field(default_factory=lambda: [MapScan()])
    objects: list[MapObject] = field(default_factory=list)
    info: list[InfoLine] = field(default_factory=list)
    origin_lat_long_alt: tuple[float, float, float] | None = None
    inactive_objects: list[str] = field(default_factory=list)
    child_objects: list[str] = field(default_factory=list)
    unknown_lines: list[str] = field(default_factory=list)
    source: str = "<map>"
    skipped_lines: int = 0
    """Data lines that did not parse and were skipped (ARIA skips them too)."""
    warnings: list[MapWarning] = field(default_factory=list)
    """The first warnings (skipped lines, ignored extra fields); ``warning_count`` counts them all."""
    warning_count: int = 0

    def __post_init__(self) -> None:
        if not self.scans:
            self.scans = [MapScan()]

    # -- the default scan -------------------------------------------------------------------------

    @property
    def scan(self) -> MapScan:
        return self.scans[0]

    @property
    def points(self) -> np.ndarray:
        return self.scans[0].points

    @points.setter
    def points(self, value: ArrayLike) -> None:
        self.scans[0].points = as_rows(value, 2, "points")

    @property
    def segments(self) -> np.ndarray:
        return self.scans[0].segments

    @segments.setter
    def segments(self, value: ArrayLike) -> None:
        self.scans[0].segments = as_rows(value, 4, "segments")

    @property
    def resolution(self) -> int | None:
        return self.scans[0].resolution

    @property
    def num_points(self) -> int:
        return len(self.scans[0].points)

    @property
    def num_lines(self) -> int:
        return len(self.scans[0].segments)

    @property
    def claimed(self) -> ScanClaims:
        return self.scans[0].claimed

    def point_bounds(self) -> Bounds | None:
        return self.scans[0].point_bounds()

    def line_bounds(self) -> Bounds | None:
        return self.scans[0].line_bounds()

    def bounds(self) -> Bounds | None:
        """Everything drawn: points and segments of every scan (None for an empty map)."""
        result: Bounds | None = None
        for scan in self.scans:
            for part in (scan.point_bounds(), scan.line_bounds()):
                if part is not None:
                    result = part.union(result)
        return result

    # -- objects ------------------------------------------------------------------------------------

    @property
    def map_info(self) -> list[str]:
        """Arguments of the active ``MapInfo:`` lines (custom type definitions)."""
        return [line.args for line in self.info if line.keyword == "MapInfo"]

    def objects_of_type(self, type_name: str) -> list[MapObject]:
        wanted = type_name.lower()
        return [obj for obj in self.objects if obj.type.lower() == wanted]

    def home(self) -> Pose | None:
        """The first ``RobotHome`` pose, where a simulated robot starts; None when the map has none."""
        homes = self.objects_of_type("RobotHome")
        return homes[0].pose if homes else None

    def goals(self) -> list[MapObject]:
        """``Goal`` and ``GoalWithHeading`` objects in map order (what ``getGoals`` lists)."""
        return [obj for obj in self.objects if obj.is_goal]

    def goal_names(self) -> list[str]:
        return [obj.name for obj in self.goals()]

    def __eq__(self, other: object) -> bool:
        """Same map content: provenance (source, warnings) and the header's stale claims do not count."""
        if not isinstance(other, MapData):
            return NotImplemented
        return (
            self.category == other.category
            and self.scans == other.scans
            and self.objects == other.objects
            and self.info == other.info
            and self.origin_lat_long_alt == other.origin_lat_long_alt
            and self.inactive_objects == other.inactive_objects
            and self.child_objects == other.child_objects
            and self.unknown_lines == other.unknown_lines
        )


def new_map(
    points: ArrayLike | None = None,
    segments: ArrayLike | None = None,
    *,
    objects: list[MapObject] | None = None,
    resolution: int | None = None,
    category: str = "2D-Map",
    info: list[InfoLine] | None = None,
    source: str = "<map>",
) -> MapData:
    """A single-scan map from arrays: the common way to build one in code."""
    scan = MapScan(
        points=as_rows(points, 2, "points"), segments=as_rows(segments, 4, "segments"), resolution=resolution
    )
    return MapData(
        category=category,
        scans=[scan],
        objects=list(objects or []),
        info=list(info or []),
        source=source,
    )

"""A small reader of ARIA's laser scan logs (``.2d``, ``LaserOdometryLog``) for the tests.

Written from the format's documentation (ARIA's ``LaserLogFileFormat`` page), apart from the
simulator's writer, so that a test reading a fresh scan checks the writer against the format rather
than against itself: a header of ``tag: values`` lines, then reading blocks (``logTime`` … ``scan1``,
the readings last) and tag blocks (``time``, the poses, then the tag's own line).
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class Reading:
    scan_id: int
    time: float
    velocities: tuple[float, ...]
    pose: tuple[float, float, float]
    global_pose: tuple[float, float, float]
    points: list[tuple[int, int]]
    """(x, y) mm in the robot's frame, one per ray; (0, 0) where the ray hit nothing."""


@dataclass
class Tag:
    time: float
    pose: tuple[float, float, float]
    text: str


@dataclass
class ScanLog:
    header: dict[str, str] = field(default_factory=dict)
    readings: list[Reading] = field(default_factory=list)
    tags: list[Tag] = field(default_factory=list)
    order: list[Reading | Tag] = field(default_factory=list)
    """Readings and tags as they follow each other in the file."""
    ended: bool = False


def _pose(values: str) -> tuple[float, float, float]:
    x, y, th = (float(v) for v in values.split())
    return x, y, th


def read_scan_log(text: str) -> ScanLog:
    lines = text.split("\n")
    if lines[0] != "LaserOdometryLog":
        raise ValueError(f"not a laser scan log: {lines[0][:40]!r}")
    log = ScanLog()
    block: dict[str, str] = {}
    kind = ""
    for line in lines[1:]:
        if not line:
            continue
        if line.startswith("#"):
            log.ended = log.ended or line == "# End of log"
            continue
        key, colon, rest = line.partition(": ")
        if (
            kind == "tag"
            and {"robot", "robotGlobal"} <= set(block)
            and not (colon and key in ("robot", "robotGlobal"))
        ):
            tag = Tag(float(block["time"]), _pose(block["robot"]), line)
            log.tags.append(tag)
            log.order.append(tag)
            block, kind = {}, ""
            continue
        if not colon:
            raise ValueError(f"a line that is neither a tag nor data: {line[:60]!r}")
        if key == "logTime":
            block, kind = {"logTime": rest}, "reading"
        elif key == "time":
            block, kind = {"time": rest}, "tag"
        elif kind:
            block[key] = rest
            if kind == "reading" and key == "scan1":
                numbers = [int(v) for v in rest.split()]
                if len(numbers) % 2:
                    raise ValueError("scan1 holds an odd count of numbers")
                reading = Reading(
                    int(block["scanId"]),
                    float(block["logTime"]),
                    tuple(float(v) for v in block["velocities"].split()),
                    _pose(block["robot"]),
                    _pose(block["robotGlobal"]),
                    list(zip(numbers[::2], numbers[1::2], strict=True)),
                )
                log.readings.append(reading)
                log.order.append(reading)
                block, kind = {}, ""
        else:
            log.header[key] = rest
    return log

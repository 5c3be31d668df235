"""Large, realistic, reproducible maps for the simulator and the benchmarks: an office building of any size.

The building is a stack of bands, each a corridor with a row of rooms on either
side; rooms have doors onto the corridor and some furniture. Walls become the
``LINES`` segments; the ``DATA`` points are what a laser would have seen: points
spread evenly along every wall and piece of furniture, with a little noise.
Everything is built with numpy, so a million points take a fraction of a
second, and the same seed always gives the same map.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rtmu.mapfile import MapData, MapObject, new_map

ROOM_DEPTH = 5000
CORRIDOR_WIDTH = 2000
BAND_HEIGHT = 2 * ROOM_DEPTH + CORRIDOR_WIDTH
DOOR_WIDTH = 900
HOME_X = 1500
"""RobotHome sits in the first corridor this far from its west end, clear of every wall."""


@dataclass(frozen=True)
class _Layout:
    walls: np.ndarray
    """Structural segments (k, 4) float64, outer walls first."""
    rooms: np.ndarray
    """Rooms (r, 5): x0, x1, back_y, front_y, band; back/front are the y of the back and door walls."""
    width: float
    height: float


def generate_map(
    points: int,
    lines: int,
    seed: int = 0,
    *,
    noise_mm: float = 8.0,
    resolution: int = 20,
    goals: int = 20,
) -> MapData:
    """A building map with exactly ``points`` points and ``lines`` segments, the same for the same seed.

    The building's size follows ``lines`` (about 3.5 segments per room; a
    quarter of the segments are furniture); with ``lines=0`` it follows
    ``points`` (~25 mm between points). Points are sorted by x then y, as
    ARIA's own laser maps are. Cairns: a RobotHome in the first corridor, up
    to ``goals`` goals in rooms (names with spaces), a Dock, a ForbiddenArea
    over one room and a ForbiddenLine across the far end of a corridor.
    """
    if points < 0 or lines < 0:
        raise ValueError("points and lines cannot be negative")
    rng = np.random.default_rng(seed)
    # Walls for three quarters of the segments (furniture gets the rest), or enough for ~25 mm spacing.
    structural_target = 0.75 * lines if lines > 0 else max(12.0, points * 25.0 / 2500.0)
    layout = _layout(rng, structural_target)
    furniture = _furniture(rng, layout.rooms, max(0, lines - len(layout.walls)))
    every = np.concatenate([layout.walls, furniture]) if len(furniture) else layout.walls
    segments = every[:lines]
    pts = points_along(every, rng, count=points, noise_mm=noise_mm)
    pts = pts[np.lexsort((pts[:, 1], pts[:, 0]))]
    result = new_map(
        pts,
        np.rint(segments),
        objects=_objects(rng, layout, goals),
        resolution=resolution,
        source=f"<generated seed={seed}>",
    )
    result.scan.points_sorted = True
    return result


def points_along(
    segments: np.ndarray,
    rng: np.random.Generator,
    *,
    count: int | None = None,
    spacing_mm: float | None = None,
    noise_mm: float = 8.0,
) -> np.ndarray:
    """Points spread evenly along ``segments`` (jittered by ``noise_mm``), as a laser map shows walls.

    Give either ``count`` (exactly that many, spread over the total length) or
    ``spacing_mm`` (each segment gets length / spacing points). Returns int32 (n, 2).
    """
    seg = np.asarray(segments, dtype=np.float64).reshape(-1, 4)
    lengths = np.hypot(seg[:, 2] - seg[:, 0], seg[:, 3] - seg[:, 1])
    if len(seg) == 0 or lengths.sum() == 0:
        if count:
            raise ValueError("cannot place points without walls")
        return np.zeros((0, 2), dtype=np.int32)
    if count is None:
        if spacing_mm is None or spacing_mm <= 0:
            raise ValueError("give count or a positive spacing_mm")
        per_segment = np.maximum(1, np.rint(lengths / spacing_mm).astype(np.int64))
        which = np.repeat(np.arange(len(seg)), per_segment)
        first = np.repeat(np.cumsum(per_segment) - per_segment, per_segment)
        along = (np.arange(len(which)) - first + 0.5) / per_segment[which]
    else:
        ends = np.cumsum(lengths)
        total = float(ends[-1])
        distance = (np.arange(count) + rng.random(count)) * (total / max(count, 1))
        which = np.minimum(np.searchsorted(ends, distance, side="right"), len(seg) - 1)
        start = ends[which] - lengths[which]
        along = np.clip((distance - start) / np.maximum(lengths[which], 1e-9), 0.0, 1.0)
    chosen = seg[which]
    xy = chosen[:, :2] + along[:, None] * (chosen[:, 2:] - chosen[:, :2])
    if noise_mm > 0:
        xy += rng.normal(0.0, noise_mm, size=xy.shape)
    return np.rint(xy).astype(np.int32)


def box_segments(x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    """The four sides of an axis-aligned box as segments (4, 4)."""
    return np.array(
        [[x0, y0, x1, y0], [x1, y0, x1, y1], [x1, y1, x0, y1], [x0, y1, x0, y0]], dtype=np.float64
    )


# -- the building ----------------------------------------------------------------------------------


def _layout(rng: np.random.Generator, structural_target: float) -> _Layout:
    # About 7 segments per band and column; columns ~4.5 m, bands 12 m: a roughly square building.
    bands = max(1, round(math.sqrt(structural_target / 18.7)))
    columns = max(1, round((structural_target - 4 * bands) / (7 * bands + 1)))
    widths = rng.integers(30, 61, size=columns) * 100.0
    xs = np.concatenate(([0.0], np.cumsum(widths)))
    width = float(xs[-1])
    height = float(bands * BAND_HEIGHT)
    x0, x1 = xs[:-1], xs[1:]
    band_y = np.arange(bands, dtype=np.float64) * BAND_HEIGHT

    walls = []
    # Outer and band-separating walls, one piece per room: y = k * BAND_HEIGHT.
    ys = np.arange(bands + 1, dtype=np.float64) * BAND_HEIGHT
    yy, cc = np.meshgrid(ys, np.arange(columns), indexing="ij")
    walls.append(np.stack([x0[cc], yy, x1[cc], yy], axis=-1).reshape(-1, 4))
    # Corridor ends (outer walls): x = 0 and x = width across each corridor.
    c0 = band_y + ROOM_DEPTH
    c1 = c0 + CORRIDOR_WIDTH
    for x in (0.0, width):
        walls.append(np.stack([np.full(bands, x), c0, np.full(bands, x), c1], axis=-1))
    # Door walls: each room's corridor side is two pieces around a door.
    offsets = rng.uniform(300.0, widths[None, None, :] - DOOR_WIDTH - 300.0, size=(bands, 2, columns))
    offsets = np.rint(offsets / 10.0) * 10.0
    door_x = x0[None, None, :] + offsets
    front_y = np.stack([c0, c1], axis=1)[:, :, None] + np.zeros((1, 1, columns))
    left = np.stack([np.broadcast_to(x0, door_x.shape), front_y, door_x, front_y], axis=-1)
    right = np.stack([door_x + DOOR_WIDTH, front_y, np.broadcast_to(x1, door_x.shape), front_y], axis=-1)
    walls.append(np.stack([left, right], axis=-2).reshape(-1, 4))
    # Side walls between rooms, both rows: x = xs[i].
    row_spans = np.stack(
        [np.stack([band_y, c0], axis=1), np.stack([c1, band_y + BAND_HEIGHT], axis=1)], axis=1
    )
    bb, rr, ii = np.meshgrid(np.arange(bands), np.arange(2), np.arange(columns + 1), indexing="ij")
    spans = row_spans[bb, rr]
    walls.append(np.stack([xs[ii], spans[..., 0], xs[ii], spans[..., 1]], axis=-1).reshape(-1, 4))

    # Rooms: row 0 has its back wall at the band's bottom, row 1 at its top.
    band, row, col = np.meshgrid(np.arange(bands), np.arange(2), np.arange(columns), indexing="ij")
    back = np.where(row == 0, band_y[band], band_y[band] + BAND_HEIGHT)
    front = np.where(row == 0, c0[band], c1[band])
    rooms = np.stack([x0[col], x1[col], back, front, band.astype(np.float64)], axis=-1).reshape(-1, 5)
    return _Layout(np.concatenate(walls), rooms, width, height)


def _furniture(rng: np.random.Generator, rooms: np.ndarray, count: int) -> np.ndarray:
    """``count`` segments of furniture: boxes (4 sides) in the back half of rooms, then shelves."""
    if count == 0:
        return np.zeros((0, 4))
    boxes, shelves = divmod(count, 4)
    parts = []
    if boxes:
        room = rooms[rng.integers(len(rooms), size=boxes)]
        x0, x1, back, front = room[:, 0], room[:, 1], room[:, 2], room[:, 3]
        inward = np.sign(front - back)
        w = np.minimum(rng.integers(5, 16, size=boxes) * 100.0, x1 - x0 - 800.0)
        h = rng.integers(4, 9, size=boxes) * 100.0
        bx = x0 + 400.0 + rng.random(boxes) * (x1 - x0 - 800.0 - w)
        depth_room = np.abs(front - back)
        near = 400.0 + rng.random(boxes) * np.maximum(depth_room / 2 - 700.0 - h, 0.0)
        by0 = back + inward * near
        by1 = by0 + inward * h
        bx, by0, bx1, by1 = np.rint(bx), np.rint(by0), np.rint(bx + w), np.rint(by1)
        sides = np.stack(
            [
                np.stack([bx, by0, bx1, by0], axis=-1),
                np.stack([bx1, by0, bx1, by1], axis=-1),
                np.stack([bx1, by1, bx, by1], axis=-1),
                np.stack([bx, by1, bx, by0], axis=-1),
            ],
            axis=1,
        )
        parts.append(sides.reshape(-1, 4))
    if shelves:
        room = rooms[rng.integers(len(rooms), size=shelves)]
        x0, x1, back, front = room[:, 0], room[:, 1], room[:, 2], room[:, 3]
        y = back + np.sign(front - back) * 300.0
        parts.append(np.stack([x0 + 400.0, y, x0 + 400.0 + np.minimum(1500.0, x1 - x0 - 800.0), y], axis=-1))
    return np.concatenate(parts)


def _objects(rng: np.random.Generator, layout: _Layout, goals: int) -> list[MapObject]:
    rooms = layout.rooms
    home_y = ROOM_DEPTH + CORRIDOR_WIDTH / 2
    objects = [MapObject("RobotHome", HOME_X, home_y, 0.0, name="Home")]
    chosen = rng.permutation(len(rooms))
    forbidden_room = rooms[chosen[0]]
    for number, index in enumerate(chosen[1 : 1 + goals], start=1):
        x0, x1, back, front, _ = rooms[index]
        inward = 1.0 if front > back else -1.0
        x = round((x0 + x1) / 2)
        y = round(front - inward * 1200.0)  # in the front half, clear of furniture
        label = f"Room {int(index) + 1}"
        if number % 3 == 0:
            # Facing the corridor: heading towards the door wall.
            objects.append(MapObject("GoalWithHeading", x, y, 90.0 * inward, name=label))
        else:
            objects.append(MapObject("Goal", x, y, 0.0, name=label))
    if layout.width > 2 * HOME_X + 1000:
        objects.append(MapObject("Dock", layout.width - HOME_X, home_y, 180.0, name="Charger"))
    fx0, fx1, fback, ffront, _ = forbidden_room
    inward = 1.0 if ffront > fback else -1.0
    objects.append(
        MapObject(
            "ForbiddenArea",
            0,
            0,
            0.0,
            name="Server room",
            from_xy=(fx0 + 200, min(fback, ffront) + 200),
            to_xy=(fx1 - 200, max(fback, ffront) - 200),
        )
    )
    last_band = math.floor(layout.height / BAND_HEIGHT) - 1
    cy0 = last_band * BAND_HEIGHT + ROOM_DEPTH
    line_x = max(layout.width - 1000.0, HOME_X + 1000.0)
    objects.append(
        MapObject(
            "ForbiddenLine",
            line_x,
            cy0,
            0.0,
            name="Stairs",
            from_xy=(line_x, cy0),
            to_xy=(line_x, cy0 + CORRIDOR_WIDTH),
        )
    )
    return objects

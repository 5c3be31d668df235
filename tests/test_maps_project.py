"""Our own maps (rtmu/data/maps): they parse, round-trip, match their generator, a robot can start at home."""

from __future__ import annotations

import numpy as np
import pytest

from rtmu.mapfile import MapData, MapObject, map_bytes, parse_map, read_map
from rtmu.package_data import MAPS_DIR
from rtmu.sim.project_maps import PROJECT_MAPS

MAPS_DIR = MAPS_DIR
HOME_CLEARANCE_MM = 500
GOAL_CLEARANCE_MM = 400


def distance_to_segments(x: float, y: float, segments: np.ndarray) -> float:
    seg = segments.astype(np.float64)
    p = seg[:, :2]
    d = seg[:, 2:] - p
    length2 = np.maximum((d**2).sum(axis=1), 1e-12)
    t = np.clip(((np.array([x, y]) - p) * d).sum(axis=1) / length2, 0.0, 1.0)
    nearest = p + t[:, None] * d
    return float(np.hypot(nearest[:, 0] - x, nearest[:, 1] - y).min())


def distance_to_points(x: float, y: float, points: np.ndarray) -> float:
    return float(np.hypot(points[:, 0] - x, points[:, 1] - y).min())


def inside_rectangle(x: float, y: float, obj: MapObject) -> bool:
    assert obj.from_xy is not None and obj.to_xy is not None and obj.th == 0
    (x1, y1), (x2, y2) = obj.from_xy, obj.to_xy
    return min(x1, x2) <= x <= max(x1, x2) and min(y1, y2) <= y <= max(y1, y2)


@pytest.fixture(scope="module", params=sorted(PROJECT_MAPS))
def project_map(request: pytest.FixtureRequest) -> tuple[str, MapData]:
    return request.param, read_map(MAPS_DIR / request.param)


def test_committed_file_is_what_the_generator_writes(project_map: tuple[str, MapData]) -> None:
    name, _ = project_map
    assert (MAPS_DIR / name).read_bytes() == map_bytes(PROJECT_MAPS[name]()), (
        "run python -m rtmu.sim.project_maps"
    )


def test_parses_cleanly_and_round_trips(project_map: tuple[str, MapData]) -> None:
    _, data = project_map
    assert data.skipped_lines == 0 and data.warning_count == 0
    assert data.num_points == data.claimed.num_points and data.num_lines == data.claimed.num_lines
    assert data.point_bounds() == data.claimed.point_bounds
    assert data.resolution == 20
    assert parse_map(map_bytes(data)) == data


def test_home_has_room_to_drive(project_map: tuple[str, MapData]) -> None:
    _, data = project_map
    home = data.home()
    assert home is not None
    assert distance_to_segments(home.x, home.y, data.segments) >= HOME_CLEARANCE_MM
    assert distance_to_points(home.x, home.y, data.points) >= HOME_CLEARANCE_MM
    for area in data.objects_of_type("ForbiddenArea"):
        assert not inside_rectangle(home.x, home.y, area)


def test_goals_are_reachable_places(project_map: tuple[str, MapData]) -> None:
    _, data = project_map
    box = data.bounds()
    assert box is not None
    assert data.goals()
    for goal in data.goals():
        assert box.min_x < goal.x < box.max_x and box.min_y < goal.y < box.max_y
        assert distance_to_segments(goal.x, goal.y, data.segments) >= GOAL_CLEARANCE_MM, goal.name
        assert distance_to_points(goal.x, goal.y, data.points) >= GOAL_CLEARANCE_MM, goal.name
        for area in data.objects_of_type("ForbiddenArea"):
            assert not inside_rectangle(goal.x, goal.y, area), goal.name


def test_points_trace_the_walls_like_a_laser_map(project_map: tuple[str, MapData]) -> None:
    _, data = project_map
    sample = data.points[:: max(1, len(data.points) // 500)]
    worst = max(distance_to_segments(float(x), float(y), data.segments) for x, y in sample)
    assert worst < 40  # 5 mm noise
    wall_length = np.hypot(
        data.segments[:, 2] - data.segments[:, 0], data.segments[:, 3] - data.segments[:, 1]
    )
    assert data.num_points == pytest.approx(wall_length.sum() / 20, rel=0.02)  # ~20 mm apart
    order = np.lexsort((data.points[:, 1], data.points[:, 0]))
    assert data.scan.points_sorted and np.array_equal(order, np.arange(len(order)))


def test_arena_is_the_thesis_room() -> None:
    data = read_map(MAPS_DIR / "arena.map")
    box = data.line_bounds()
    assert box is not None
    assert (box.max_x - box.min_x, box.max_y - box.min_y) == (6000, 5000)
    assert data.goal_names() == ["Goal", "Far corner"]
    home, goal = data.home(), data.goals()[0]
    assert home is not None and home.x - box.min_x <= 1500  # near one side
    assert goal.x - home.x >= 3500  # across the room
    boxes_between = [s for s in data.segments[4:] if home.x < min(s[0], s[2]) and max(s[0], s[2]) < goal.x]
    assert len(boxes_between) >= 12  # at least three boxes of four sides


def test_office_floor() -> None:
    data = read_map(MAPS_DIR / "office.map")
    box = data.line_bounds()
    assert box is not None
    assert (box.max_x - box.min_x, box.max_y - box.min_y) == (30000, 12000)
    names = data.goal_names()
    assert len(names) >= 5 and sum(" " in n for n in names) >= 3
    assert len(data.objects_of_type("ForbiddenArea")) == 1 and len(data.objects_of_type("ForbiddenLine")) == 1
    home = data.home()
    assert home is not None and 5000 < home.y < 7000  # in the corridor
    assert data.objects_of_type("SlowArea") and "SlowArea" in data.map_info[0]
    # Door gaps: the corridor's walls are broken into pieces, one gap per room.
    corridor_walls = [s for s in data.segments if s[1] == s[3] and s[1] in (5000, 7000)]
    covered = sum(abs(int(s[2]) - int(s[0])) for s in corridor_walls)
    assert covered == 2 * 30000 - 12 * 1000

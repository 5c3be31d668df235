"""The path planner on its own: safe paths on the office map, forbidden cairns, blocked ways, big maps."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from rtmu.mapfile import MapObject
from rtmu.sim import p3dx
from rtmu.sim.geometry import Obstacles
from rtmu.sim.mapgen import generate_map
from rtmu.sim.planner import GridCache, NoPath, Plan, PlanGrid, forbidden_shapes
from rtmu.sim.project_maps import office_map

OFFICE = office_map()
HOME = (2000.0, 6000.0)


@pytest.fixture(scope="module")
def grid() -> PlanGrid:
    return PlanGrid(OFFICE.segments, OFFICE.points, OFFICE.objects)


def _samples(plan: Plan, step_mm: float = 10.0) -> np.ndarray:
    """Points every ``step_mm`` along the whole path."""
    pts = np.asarray(plan.points, dtype=np.float64)
    out = [pts[:1]]
    for a, b in itertools.pairwise(pts):
        n = max(int(math.hypot(*(b - a)) / step_mm), 1)
        t = np.linspace(0.0, 1.0, n + 1)[1:, None]
        out.append(a + (b - a) * t)
    return np.concatenate(out)


def _crosses(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> bool:
    def side(p: np.ndarray, q: np.ndarray, r: np.ndarray) -> float:
        return float((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]))

    return side(a, b, c) * side(a, b, d) < 0 and side(c, d, a) * side(c, d, b) < 0


GOALS = [o for o in OFFICE.objects if o.is_goal or o.type == "Dock"]


@pytest.mark.parametrize("goal", GOALS, ids=lambda o: o.name)
def test_paths_keep_the_whole_robot_clear_of_walls(grid: PlanGrid, goal: MapObject) -> None:
    plan = grid.plan(HOME, (goal.x, goal.y))
    assert plan.points[0] == HOME and plan.points[-1] == (goal.x, goal.y)
    walls = Obstacles(OFFICE.segments, OFFICE.points, point_cell_mm=20.0)
    for x, y in _samples(plan):
        assert walls.clearance(x, y, p3dx.RADIUS_MM) == math.inf, (goal.name, x, y)
    straight = math.dist(HOME, (goal.x, goal.y))
    assert straight <= plan.length_mm <= 1.6 * straight + 2000  # shortest, not a detour
    assert len(plan.points) <= 8  # smoothed down to its corners


def test_paths_never_cross_forbidden_lines_or_enter_forbidden_areas(grid: PlanGrid) -> None:
    lines, areas = forbidden_shapes(OFFICE.objects)
    assert len(lines) == 1 and len(areas) == 1
    (x0, y0), (x1, y1) = areas[0].min(axis=0), areas[0].max(axis=0)
    # Lab B sits just east of the server room and Corridor End just west of the stairs' line.
    for start, goal in [((12000.0, 9000.0), (22500.0, 9000.0)), (HOME, (26500.0, 6000.0))]:
        plan = grid.plan(start, goal)
        s = _samples(plan)
        inside = (s[:, 0] >= x0 - p3dx.RADIUS_MM) & (s[:, 0] <= x1 + p3dx.RADIUS_MM)
        inside &= (s[:, 1] >= y0 - p3dx.RADIUS_MM) & (s[:, 1] <= y1 + p3dx.RADIUS_MM)
        assert not inside.any()
        pts = np.asarray(plan.points)
        for a, b in itertools.pairwise(pts):
            for line in lines:
                assert not _crosses(a, b, line[:2], line[2:])
    with pytest.raises(NoPath):
        grid.plan(HOME, (17000.0, 9500.0))  # inside the area
    with pytest.raises(NoPath):
        grid.plan(HOME, (29000.0, 6000.0))  # behind the line: the stairs' landing


def test_without_the_forbidden_cairns_the_same_goals_are_reachable() -> None:
    """So the refusals above come from the cairns, not from walls."""
    plain = PlanGrid(OFFICE.segments, OFFICE.points, [])
    assert plain.plan(HOME, (29000.0, 6000.0)).points[-1] == (29000.0, 6000.0)
    assert plain.plan(HOME, (17000.0, 9500.0)).points[-1] == (17000.0, 9500.0)


def test_unreachable_and_occupied_goals_are_refused(grid: PlanGrid) -> None:
    with pytest.raises(NoPath, match="not clear"):
        grid.plan(HOME, (1250.0, 550.0))  # against a desk in Room 101
    with pytest.raises(NoPath, match="not clear"):
        grid.plan(HOME, (40000.0, 6000.0))  # off the map
    boxed = PlanGrid(
        np.concatenate([OFFICE.segments, [[24000, 5000, 24000, 7000]]]), OFFICE.points, OFFICE.objects
    )
    with pytest.raises(NoPath, match="no way"):
        boxed.plan(HOME, (26500.0, 6000.0))


def test_sonar_echoes_block_like_walls(grid: PlanGrid) -> None:
    free = grid.plan(HOME, (12000.0, 6000.0))
    assert len(free.points) == 2  # straight down the corridor
    echoes = np.array([[8000.0, y] for y in range(5000, 6001, 50)])  # a trolley across half of it
    around = grid.plan(HOME, (12000.0, 6000.0), echoes)
    assert min(abs(y - 6000.0) for _, y in around.points[1:-1]) > 300  # it swerves to the free side
    assert all(math.dist(p, e) > p3dx.RADIUS_MM for p in _samples(around) for e in echoes)
    wall = np.array([[8000.0, y] for y in range(5000, 7001, 50)])
    with pytest.raises(NoPath):
        grid.plan(HOME, (12000.0, 6000.0), wall)


def test_a_start_just_inside_the_margin_still_plans(grid: PlanGrid) -> None:
    plan = grid.plan((2000.0, 5300.0), (6000.0, 6000.0))  # 300 mm from the corridor's south wall
    assert plan.points[0] == (2000.0, 5300.0) and plan.points[-1] == (6000.0, 6000.0)


def test_the_grid_is_built_once_per_map() -> None:
    cache = GridCache()
    built: list[int] = []

    def build() -> PlanGrid:
        built.append(1)
        return PlanGrid(OFFICE.segments, OFFICE.points, OFFICE.objects)

    first = cache.get(b"md5-a", build)
    assert cache.get(b"md5-a", build) is first and len(built) == 1
    assert cache.get(b"md5-b", build) is not first and len(built) == 2


def test_big_maps_plan_coarse_first_and_agree_with_a_whole_search() -> None:
    data = generate_map(200_000, 2_000, seed=5)
    big = PlanGrid(data.segments, data.points, data.objects)
    assert big.costs.size > 1_500_000  # takes the coarse-first road
    home = data.home()
    assert home is not None
    dock = next(o for o in data.objects if o.type == "Dock")
    plan = big.plan((home.x, home.y), (dock.x, dock.y))
    whole = big.plan((home.x, home.y), (dock.x, dock.y), coarse_first=False)
    assert plan.points[-1] == whole.points[-1] == (dock.x, dock.y)
    assert plan.length_mm <= 1.02 * whole.length_mm
    walls = Obstacles(data.segments, data.points)
    for x, y in _samples(plan, 50.0):
        assert walls.clearance(x, y, p3dx.RADIUS_MM) == math.inf


def test_in_an_open_hall_paths_go_around_a_forbidden_area_and_a_forbidden_line() -> None:
    hall = np.array(
        [[0, 0, 10000, 0], [10000, 0, 10000, 10000], [10000, 10000, 0, 10000], [0, 10000, 0, 0]], float
    )
    area = MapObject("ForbiddenArea", 0, 0, 0.0, name="Wet floor", from_xy=(4000, 3000), to_xy=(6000, 7000))
    line = MapObject("ForbiddenLine", 0, 0, 0.0, name="Tape", from_xy=(8000, 0), to_xy=(8000, 6000))
    start, goal = (1000.0, 5000.0), (9000.0, 1000.0)
    straight = PlanGrid(hall, np.zeros((0, 2)), [])
    assert len(straight.plan(start, goal).points) == 2  # nothing in the way without the cairns
    plan = PlanGrid(hall, np.zeros((0, 2)), [area, line]).plan(start, goal)
    s = _samples(plan)
    r = p3dx.RADIUS_MM
    assert not (
        (s[:, 0] > 4000 - r) & (s[:, 0] < 6000 + r) & (s[:, 1] > 3000 - r) & (s[:, 1] < 7000 + r)
    ).any()
    pts = np.asarray(plan.points)
    for a, b in itertools.pairwise(pts):
        assert not _crosses(a, b, np.array([8000.0, 0.0]), np.array([8000.0, 6000.0]))
    assert max(y for _, y in plan.points) > 6000 + r  # round the line's open end

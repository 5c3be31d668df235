"""The building generator: exact counts, same map for the same seed, and a map a robot can use."""

from __future__ import annotations

import numpy as np
import pytest

from rtmu.mapfile import map_bytes, parse_map
from rtmu.sim.mapgen import box_segments, generate_map, points_along
from test_maps_project import distance_to_points, distance_to_segments


@pytest.mark.parametrize(
    ("points", "lines"), [(0, 0), (1, 0), (100, 0), (0, 5), (1000, 3), (5000, 50), (20000, 777), (3000, 4000)]
)
def test_exact_counts(points: int, lines: int) -> None:
    data = generate_map(points, lines, seed=5)
    assert data.num_points == points and data.num_lines == lines
    assert data.points.dtype == np.int32 and data.segments.dtype == np.int32
    assert parse_map(map_bytes(data)) == data


def test_same_seed_same_map_other_seed_other_map() -> None:
    a = generate_map(20_000, 400, seed=11)
    b = generate_map(20_000, 400, seed=11)
    c = generate_map(20_000, 400, seed=12)
    assert a == b and map_bytes(a) == map_bytes(b)
    assert a != c
    assert not np.array_equal(a.points, c.points)


def test_looks_like_a_building() -> None:
    data = generate_map(50_000, 1200, seed=3)
    box = data.line_bounds()
    assert box is not None
    width, height = box.max_x - box.min_x, box.max_y - box.min_y
    assert 0.5 < width / height < 2.0  # roughly square, not a strip
    assert width > 20_000
    # Walls are axis-aligned like a floor plan; points lie on them (8 mm noise).
    seg = data.segments
    assert np.all((seg[:, 0] == seg[:, 2]) | (seg[:, 1] == seg[:, 3]))
    sample = data.points[::500]
    assert max(distance_to_segments(float(x), float(y), seg) for x, y in sample) < 50
    order = np.lexsort((data.points[:, 1], data.points[:, 0]))
    assert data.scan.points_sorted and np.array_equal(order, np.arange(len(order)))


def test_cairns() -> None:
    data = generate_map(30_000, 900, seed=9, goals=12)
    home = data.home()
    assert home is not None
    assert distance_to_segments(home.x, home.y, data.segments) >= 500
    assert distance_to_points(home.x, home.y, data.points) >= 500
    names = data.goal_names()
    assert len(names) == 12 and len(set(names)) == 12 and all(" " in n for n in names)
    for goal in data.goals():
        assert distance_to_segments(goal.x, goal.y, data.segments) >= 400, goal.name
    assert len(data.objects_of_type("ForbiddenArea")) == 1
    assert len(data.objects_of_type("ForbiddenLine")) == 1
    assert len(data.objects_of_type("Dock")) == 1


def test_points_along() -> None:
    rng = np.random.default_rng(0)
    walls = box_segments(0, 0, 1000, 500)
    spaced = points_along(walls, rng, spacing_mm=20, noise_mm=0)
    assert len(spaced) == 150
    assert distance_to_segments(float(spaced[0, 0]), float(spaced[0, 1]), walls) == 0
    assert len(points_along(walls, rng, count=7)) == 7
    with pytest.raises(ValueError):
        points_along(np.zeros((0, 4)), rng, count=3)
    with pytest.raises(ValueError):
        generate_map(-1, 0)

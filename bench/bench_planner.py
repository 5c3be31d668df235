"""What a plan costs the simulator's path planner (``rtmu.sim.planner``), and how good the paths are.

* ``planner.grid_build_ms.{office,million}``: building the inflated occupancy grid of the office map
  and of the generated 1 M-point building (``mapgen.generate_map(1_000_000, 5_000, seed=3)``,
  160 m × 170 m).
* ``planner.plan_ms.{office,million}``: one plan with the map's grid already built (the simulator
  keeps it per map), the mean over routes from the home cairn to every reachable goal and dock and
  to a few fixed points (each route the best of 3). Baseline: the same plan building the grid every
  time, as a planner without the cache would. On the big map the coarse route comes first and the
  fine grid is searched piece by piece along it; ``planner.plan_ms.million_whole_search`` is the
  same routes searched over the whole fine grid at once (baseline of that figure: the coarse-first
  plan). Target: at most 200 ms per plan on the big map after the first.
* ``planner.path_over_straight.{office,million}``: smoothed path length over straight-line distance,
  mean over the same routes (1.0 would be a straight line; walls make it longer).
"""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Callable

from bench.common import Result
from rtmu.mapfile import MapData
from rtmu.sim.mapgen import generate_map
from rtmu.sim.planner import NoPath, PlanGrid
from rtmu.sim.project_maps import office_map

Point = tuple[float, float]


def _build(data: MapData) -> PlanGrid:
    return PlanGrid(data.segments, data.points, data.objects)


def _routes(data: MapData, grid: PlanGrid, extra: list[Point]) -> list[tuple[Point, Point]]:
    home = data.home()
    assert home is not None
    start = (float(home.x), float(home.y))
    ends = [(float(o.x), float(o.y)) for o in data.objects if o.is_goal or o.type == "Dock"] + extra
    routes = []
    for end in ends:
        try:
            grid.plan(start, end)
        except NoPath:
            continue  # another band of the generated building: no way there, by design
        routes.append((start, end))
    return routes


def _best_ms(fn: Callable[[], object], repeat: int = 3) -> float:
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best * 1000.0


def _figures(name: str, data: MapData, extra: list[Point], rebuild_repeat: int) -> list[Result]:
    t0 = time.perf_counter()
    grid = _build(data)
    build_ms = (time.perf_counter() - t0) * 1000.0
    routes = _routes(data, grid, extra)
    cached = [_best_ms(lambda a=a, b=b: grid.plan(a, b)) for a, b in routes]
    rebuilt = [
        _best_ms(lambda a=a, b=b: _build(data).plan(a, b), repeat=1) for a, b in routes[:rebuild_repeat]
    ]
    detour = [grid.plan(a, b).length_mm / math.dist(a, b) for a, b in routes]
    cached_mean = statistics.fmean(cached)
    out = [
        Result(f"planner.grid_build_ms.{name}", build_ms, "ms"),
        Result(
            f"planner.plan_ms.{name}",
            cached_mean,
            "ms",
            baseline=statistics.fmean(rebuilt) if rebuilt else None,
        ),
        Result(f"planner.path_over_straight.{name}", statistics.fmean(detour), "ratio"),
        Result(f"planner.routes.{name}", len(routes), "routes"),
    ]
    if grid.costs.size > 1_500_000:
        whole = [_best_ms(lambda a=a, b=b: grid.plan(a, b, coarse_first=False), repeat=1) for a, b in routes]
        out.append(Result(f"planner.plan_ms.{name}_whole_search", statistics.fmean(whole), "ms", cached_mean))
    return out


def run() -> list[Result]:
    office = office_map()
    results = _figures("office", office, [(28000.0 - 1500.0, 6500.0), (12000.0, 9000.0)], rebuild_repeat=10)
    big = generate_map(1_000_000, 5_000, seed=3)
    far = [(80000.0, 6000.0), (150000.0, 6500.0), (40000.0, 5500.0)]  # along the first corridor
    results += _figures("million", big, far, rebuild_repeat=2)
    return results

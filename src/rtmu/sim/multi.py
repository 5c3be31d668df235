"""Several simulated robots on one map: ``rtmu sim --robots N``.

Each robot is a whole ARIA server of its own (as real robots are: one ArNetworking
server per robot), on its own port — consecutive from the first one given, or each a
free port when that is 0 — with its own seed and its own start pose, clear of the walls and off the map's home
(``sim.start_spots``). Names are ``robot1`` … ``robotN``: what a fleet profile or the window's robot
list calls them.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from .config import SimConfig
from .mapserve import load_map
from .server import SimServer
from .start_spots import fleet_start_poses
from .thread import SimThread

MAX_ROBOTS = 50
"""More simulated robots than this in one process is a mistake, not a fleet."""


@dataclass(frozen=True, slots=True)
class SimRobot:
    """One robot of a simulated fleet: its name and its server's configuration."""

    name: str
    config: SimConfig


def robot_name(index: int) -> str:
    """``robot1`` for index 0: the names ``--robots N`` gives."""
    return f"robot{index + 1}"


def map_home(path: Path | None) -> tuple[float, float, float]:
    """The map's ``RobotHome`` (x, y mm, th deg), or the origin."""
    if path is None:
        return (0.0, 0.0, 0.0)
    from ..mapfile import read_map

    home = read_map(path).home()
    return (float(home.x), float(home.y), float(home.th)) if home is not None else (0.0, 0.0, 0.0)


def start_poses(base: SimConfig, count: int) -> list[tuple[float, float, float]]:
    """Where ``count`` robots start: along home's heading, apart and clear of walls (``start_spots``)."""
    home = base.start_pose or map_home(base.map_path)
    if base.map_path is None:
        return fleet_start_poses(home, count, None)
    served = load_map(base.map_path)
    segments = served.segments
    bounds = None
    if len(segments):
        xs, ys = segments[:, [0, 2]], segments[:, [1, 3]]
        bounds = (float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max()))
    markers = tuple((float(o.pose.x), float(o.pose.y)) for o in served.objects if not o.has_from_to)
    return fleet_start_poses(home, count, served.obstacles(), bounds=bounds, markers=markers)


def fleet_configs(base: SimConfig, count: int) -> list[SimRobot]:
    """``count`` robots like ``base``: consecutive ports, seeds and start poses of their own."""
    if not 1 <= count <= MAX_ROBOTS:
        raise ValueError(f"--robots must be 1…{MAX_ROBOTS}, not {count}")
    if base.port and base.port + count - 1 > 65535:
        raise ValueError(f"ports {base.port}…{base.port + count - 1} do not all exist")
    robots = []
    for i, pose in enumerate(start_poses(base, count)):
        config = dataclasses.replace(
            base,
            port=base.port + i if base.port else 0,
            seed=base.seed + i,
            start_pose=pose,
        )
        robots.append(SimRobot(robot_name(i), config))
    return robots


class SimFleet:
    """N simulated robots on one asyncio loop (``rtmu sim --robots N``): start and stop together."""

    def __init__(self, robots: Sequence[SimRobot]) -> None:
        self.robots = tuple(robots)
        self.servers = [SimServer(r.config) for r in self.robots]

    async def start(self) -> None:
        """Start every server; on failure the ones started are stopped again before raising."""
        started: list[SimServer] = []
        try:
            for server in self.servers:
                await server.start()
                started.append(server)
        except BaseException:
            for server in started:
                await server.stop()
            raise

    async def stop(self) -> None:
        for server in self.servers:
            await server.stop()


class SimFleetThreads:
    """N simulators, each on its own thread (tests, benchmarks, ``rtmu --demo --robots N``)."""

    def __init__(self, robots: Sequence[SimRobot]) -> None:
        self.robots = tuple(robots)
        self.sims = [SimThread(r.config) for r in self.robots]

    def start(self) -> SimFleetThreads:
        try:
            for sim in self.sims:
                sim.start()
        except BaseException:
            self.stop()
            raise
        return self

    def stop(self) -> None:
        for sim in self.sims:
            sim.stop()

    def __enter__(self) -> SimFleetThreads:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def endpoints(self) -> list[tuple[str, int]]:
        """(name, port) of each robot, in order."""
        return [(r.name, sim.port) for r, sim in zip(self.robots, self.sims, strict=True)]

"""How far the simulated P3-DX rolls once told to stop: ``stop`` and zero ratios brake alike, at the
robot's TransDecel (300 mm/s², the Pioneer firmware's default; see ``sim.p3dx``), as the capture shows."""

from __future__ import annotations

import numpy as np
import pytest

from rtmu.sim import p3dx
from rtmu.sim.geometry import Obstacles
from rtmu.sim.world import PHYSICS_DT, World

HALL = np.array([[0, 0, 40000, 0], [40000, 0, 40000, 4000], [40000, 4000, 0, 4000], [0, 4000, 0, 0]])


def at_full_speed() -> World:
    world = World(Obstacles(HALL), home=(1000, 2000, 0), drive_timeout=0)
    world.ratio_drive(100, 0, 100)
    for _ in range(round(6.0 / PHYSICS_DT)):
        world.step()
    assert world.body.vel == pytest.approx(p3dx.TRANS_VEL_MAX)
    return world


def rolled(world: World) -> tuple[float, float]:
    """Distance (mm) and time (s) until the robot stands."""
    x0, steps = world.body.x, 0
    while not world.body.is_stopped():
        world.step()
        steps += 1
        assert steps < 100 / PHYSICS_DT
    return world.body.x - x0, steps * PHYSICS_DT


@pytest.mark.parametrize("how", ["stop", "zero ratios"])
def test_a_stop_and_zero_ratios_brake_at_transdecel(how: str) -> None:
    world = at_full_speed()
    if how == "stop":
        world.stop()
    else:
        world.ratio_drive(0, 0, 100)
    distance, seconds = rolled(world)
    v, a = p3dx.TRANS_VEL_MAX, p3dx.TRANS_DECEL
    assert distance == pytest.approx(v * v / (2 * a), rel=0.02)  # 3.75 m
    assert seconds == pytest.approx(v / a, rel=0.02)  # 5 s


def test_a_robot_configured_to_brake_harder_stops_sooner() -> None:
    world = at_full_speed()
    world.body.trans_decel = 600.0  # what "Robot config/TransDecel" sets
    world.stop()
    distance, _ = rolled(world)
    assert distance == pytest.approx(p3dx.TRANS_VEL_MAX**2 / 1200, rel=0.02)

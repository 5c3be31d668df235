"""The robot model without sockets: walls are never crossed, the battery drains, the numbers are a P3-DX's."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from rtmu.sim import p3dx
from rtmu.sim.geometry import Obstacles
from rtmu.sim.world import World

ROOM = np.array(
    [
        [0, 0, 6000, 0],
        [6000, 0, 6000, 4000],
        [6000, 4000, 0, 4000],
        [0, 4000, 0, 0],
        [2500, 1500, 3500, 2500],  # a diagonal wall in the middle
    ]
)
POINTS = np.array([[4500 + i * 20, 800] for i in range(20)])  # a row of map points (a low shelf)


def _min_clearance(world: World) -> float:
    return world.obstacles.clearance(world.body.x, world.body.y, 5000.0)


@settings(max_examples=25, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.floats(-100, 100),
            st.floats(-100, 100),
            st.floats(0, 100),
            st.integers(5, 60),
            st.booleans(),
        ),
        min_size=1,
        max_size=8,
    )
)
def test_no_command_sequence_ever_puts_the_robot_into_a_wall(commands):
    world = World(Obstacles(ROOM, POINTS), home=(1000, 2000, 0), drive_timeout=0)
    for trans, rot, throttle, steps, safe in commands:
        world.set_safe_drive(safe)
        world.ratio_drive(trans, rot, throttle)
        for _ in range(steps * 10):
            world.step()
            assert _min_clearance(world) >= p3dx.RADIUS_MM - 1e-6


def test_acceleration_rotation_and_stop_match_the_captured_p3dx():
    world = World(Obstacles(ROOM), home=(1000, 2000, 0))
    world.ratio_drive(50, 0, 100)
    for _ in range(100):
        world.step()
    assert abs(world.body.vel - 300) < 1e-6  # 30 mm/s every 100 ms, as in drive-tcponly.poses.txt
    world.ratio_drive(0, 20, 100)
    for _ in range(100):
        world.step()
    assert abs(world.body.rot_vel - 10) < 1e-6 and abs(world.body.vel) < 1e-6
    world.stop()
    for _ in range(100):
        world.step()
    assert world.body.is_stopped() and world.strings() == ("Stopped", "Stop", "Stopped")


def test_battery_drains_faster_when_driving_and_shutdown_stops_the_robot():
    idle = World(Obstacles(np.zeros((0, 4))))
    moving = World(Obstacles(np.zeros((0, 4))), drive_timeout=0)
    moving.ratio_drive(100, 0, 100)
    for _ in range(6000):
        idle.step()
        moving.step()
    assert p3dx.BATTERY_FULL_V > idle.body.battery_v > moving.body.battery_v
    low = World(Obstacles(np.zeros((0, 4))), drive_timeout=0, battery_v=p3dx.BATTERY_SHUTDOWN_V + 0.0001)
    low.ratio_drive(100, 0, 100)
    for _ in range(200):
        low.step()
    assert low.mode is low.stop_mode
    assert low.changes.popups_created and low.changes.popups_created[0].title == "Low battery"


def test_a_flat_battery_never_lets_a_drive_move_the_robot_even_one_step():
    flat = World(Obstacles(np.zeros((0, 4))), drive_timeout=0)
    flat.set_battery(p3dx.BATTERY_SHUTDOWN_V - 0.5)
    flat.ratio_drive(100, 0, 100)
    for _ in range(5):
        flat.step()
        assert flat.body.vel == 0.0 and flat.body.x == 0.0  # a status would show any step's speed
    assert flat.mode is flat.stop_mode


def test_map_points_are_obstacles_for_the_body_and_the_sonar():
    from rtmu.sim.sonar import sonar_ranges

    world = World(Obstacles(ROOM, POINTS), home=(4700, 1500, -90), drive_timeout=0)
    ranges = sonar_ranges(world.obstacles, world.body.x, world.body.y, world.body.th)
    # Discs 3 and 4 face the shelf 700 mm "ahead" (south); it is nearer than the room wall beyond.
    assert 450 < min(ranges[3], ranges[4]) < 700
    world.set_safe_drive(False)
    world.ratio_drive(50, 0, 100)
    for _ in range(500):
        world.step()
    assert world.body.stalled and math.isclose(world.body.y, 800 + 250, abs_tol=45)

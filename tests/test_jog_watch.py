"""Every jog ends with an outcome the operator can read, worked out from the robot's own motion."""

from __future__ import annotations

from dataclasses import replace

from rtmu.control.jog_watch import START_S, JogWatch, obstacle_ahead
from rtmu.values.state import RobotState

START = RobotState(x=1000.0, y=2000.0, th=0.0, status="Moving 2000 mm")


def settle(watch: JogWatch, robot: RobotState, t: float) -> str | None:
    """The robot stands at ``robot`` from ``t`` on: what the watch says by ``t + 1`` s."""
    said = None
    for k in range(11):
        said = watch.update(replace(robot, vel=0.0, rot_vel=0.0), t + 0.1 * k) or said
    return said


def test_a_move_that_arrives_says_how_far_it_went() -> None:
    watch = JogWatch()
    watch.start("move", 2000.0, START, 0.0)
    assert watch.update(replace(START, x=1500.0, vel=400.0), 1.0) is None
    assert settle(watch, replace(START, x=2995.0), 5.0) == "Went 2.00 m"
    assert watch.jog is None


def test_a_move_stopped_short_by_an_echo_ahead_says_so_with_the_distance() -> None:
    watch = JogWatch()
    watch.start("move", 2000.0, START, 0.0)
    watch.update(replace(START, x=1300.0, vel=300.0), 1.0)
    wall = replace(START, x=1580.0, sonar=((2100, 2000), (2100, 2100), (1580, 3000)))
    assert settle(watch, wall, 2.0) == "Stopped by an obstacle 0.5 m ahead after 0.58 m of 2.00 m"


def test_a_stall_and_a_plain_short_stop_are_told_apart() -> None:
    watch = JogWatch()
    watch.start("move", -1000.0, START, 0.0)
    watch.update(replace(START, x=900.0, vel=-200.0), 0.5)
    said = settle(watch, replace(START, x=700.0, status="Stalled"), 2.0)
    assert said == "Stopped: the robot stalled after 0.30 m of 1.00 m. Look before driving on."
    watch.start("move", 1000.0, START, 0.0)
    watch.update(replace(START, x=1100.0, vel=200.0), 0.5)
    assert settle(watch, replace(START, x=1400.0), 2.0) == "Stopped short after 0.40 m of 1.00 m"


def test_turns_say_how_far_they_turned() -> None:
    watch = JogWatch()
    watch.start("turn", 90.0, replace(START, th=170.0), 0.0)
    watch.update(replace(START, th=-150.0, rot_vel=40.0), 1.0)
    assert settle(watch, replace(START, th=-100.0), 2.0) == "Turned 90°"  # across ±180
    watch.start("turn", -90.0, START, 0.0)
    watch.update(replace(START, th=-20.0, rot_vel=-40.0), 1.0)
    assert settle(watch, replace(START, th=-45.0), 2.0) == "Turn stopped after 45° of 90°"


def test_a_jog_that_never_moves_says_so_and_one_taken_over_says_by_what() -> None:
    watch = JogWatch()
    watch.start("move", 500.0, START, 0.0)
    assert watch.update(START, START_S - 0.1) is None
    assert (
        watch.update(START, START_S + 0.1)
        == "Go a distance did not start: the robot did not move (Moving 2000 mm)"
    )
    watch.start("move", 2000.0, START, 0.0)
    watch.update(replace(START, x=1400.0, vel=300.0), 1.0)
    assert watch.end("STOP", replace(START, x=1400.0)) == "Go a distance ended by STOP after 0.40 m of 2.00 m"
    assert watch.end("STOP", START) is None, "said once"


def test_only_echoes_in_the_robots_way_count() -> None:
    robot = replace(START, th=90.0, sonar=((1000, 2600), (1600, 2100), (1000, 1400)))
    assert obstacle_ahead(robot, forwards=True) == 600.0
    assert obstacle_ahead(robot, forwards=False) == 600.0
    assert obstacle_ahead(replace(robot, sonar=((1600, 2100),)), forwards=True) is None, "beside, not ahead"

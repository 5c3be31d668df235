"""The robot's limits behind the near-people cap and the stopping distance (GTK-free)."""

from __future__ import annotations

import pytest

from rtmu.client.config_feed import ConfigSection, ServerConfig
from rtmu.control.motion_limits import (
    ASSUMED_DECEL_MM_S2,
    ASSUMED_MAX_MM_S,
    REACTION_S,
    RobotLimits,
    capped_throttle,
    limits_from_config,
)
from rtmu.protocol.payloads.config import ConfigParam, ParamType


def config(**params: object) -> ServerConfig:
    made = tuple(ConfigParam(name, ParamType.INT, value) for name, value in params.items())  # type: ignore[arg-type]
    return ServerConfig(
        (ConfigSection("Teleop", "", ()), ConfigSection("Robot config", "", made)), 0, "V4", 0
    )


def test_without_a_configuration_the_limits_are_arias_p3dx() -> None:
    limits = limits_from_config(config())
    assert (limits.max_speed, limits.decel) == (ASSUMED_MAX_MM_S, ASSUMED_DECEL_MM_S2) == (2200.0, 300.0)
    assert limits.source.startswith("assumed")


def test_the_servers_robot_config_gives_the_top_speed_and_the_braking() -> None:
    limits = limits_from_config(config(TransVelMax=1500, TransDecel=600))
    assert (limits.max_speed, limits.decel) == (1500.0, 600.0)
    assert "TransVelMax" in limits.source and "TransDecel" in limits.source
    assert limits_from_config(config(TransVelMax=0)).max_speed == ASSUMED_MAX_MM_S, "0 is 'the robot's own'"


def test_the_cap_lowers_the_throttle_from_the_top_speed_and_never_raises_it() -> None:
    limits = RobotLimits(max_speed=1500.0)
    assert capped_throttle(70.0, 250, limits) == pytest.approx(100 * 250 / 1500)
    assert capped_throttle(10.0, 250, limits) == 10.0, "already slower than the cap"
    assert capped_throttle(70.0, None, limits) == 70.0, "no cap"
    assert capped_throttle(100.0, 250, RobotLimits()) * ASSUMED_MAX_MM_S / 100 == pytest.approx(250.0)


def test_a_faster_robot_than_believed_raises_its_top_speed_so_the_cap_still_holds() -> None:
    limits = RobotLimits(max_speed=1000.0)
    assert limits.seen(400.0, 100.0, 50.0) is limits, "400 mm/s at half throttle fits 1000 mm/s"
    faster = limits.seen(900.0, 100.0, 50.0)
    assert faster.max_speed == pytest.approx(1800.0) and faster.source.startswith("seen")
    assert capped_throttle(100.0, 250, faster) * faster.max_speed / 100 == pytest.approx(250.0)
    assert limits.seen(30.0, 100.0, 1.0) is limits, "creeping says nothing"
    assert limits.seen(900.0, 0.0, 50.0) is limits, "turning on the spot says nothing"


def test_the_stopping_distance_is_reaction_then_braking_at_transdecel() -> None:
    limits = RobotLimits()
    assert limits.stopping_distance(0.0) == 0.0
    assert limits.stopping_distance(1500.0) == pytest.approx(1500 * REACTION_S + 1500**2 / 600)
    assert limits.stopping_distance(-750.0) == limits.stopping_distance(750.0)
    assert RobotLimits(decel=600.0).stopping_distance(1500.0) < limits.stopping_distance(1500.0)

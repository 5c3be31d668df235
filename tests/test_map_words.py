"""The map in words (``ui.map_words``): what a screen reader hears, rounded so it changes only materially."""

from __future__ import annotations

from rtmu.model.observables import ConnectionState, NavState, Phase, RobotState
from rtmu.ui.map_words import map_description

CONNECTED = ConnectionState(phase=Phase.CONNECTED)


def robot(**kw: object) -> RobotState:
    base: dict[str, object] = dict(
        x=2000.0, y=6000.0, th=0.0, battery_v=12.8, battery_low=11.5, battery_shutdown=11.0,
        mode="Stop", numbers_at=1.0,
    )  # fmt: skip
    base.update(kw)
    return RobotState(**base)  # type: ignore[arg-type]


def test_it_says_pose_mode_battery_and_activity() -> None:
    text = map_description(robot(), NavState(), CONNECTED)
    assert (
        text
        == "Robot at x 2.0, y 6.0 metres, heading 0 degrees; mode Stop; battery 12.8 volts; standing still"
    )


def test_small_moves_say_nothing_new_and_material_ones_do() -> None:
    before = map_description(robot(), NavState(), CONNECTED)
    assert map_description(robot(x=2100.0, th=4.0), NavState(), CONNECTED) == before
    assert map_description(robot(x=2600.0), NavState(), CONNECTED) != before
    assert map_description(robot(th=30.0), NavState(), CONNECTED) != before


def test_colour_states_are_words() -> None:
    low = map_description(robot(battery_v=11.4), NavState(), CONNECTED)
    assert "battery 11.4 volts, low" in low
    lost = map_description(robot(), NavState(loc_state="Lost", loc_score=0.1), CONNECTED)
    assert lost.endswith("localization lost")


def test_going_somewhere_and_not_connected() -> None:
    nav = NavState(navigating=True, target="Lab B", remaining_mm=12_400.0)
    assert "going to Lab B, 12 metres left" in map_description(robot(vel=300.0), nav, CONNECTED)
    assert map_description(robot(), NavState(), ConnectionState()).startswith("Not connected")

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


def test_the_description_is_worded_again_only_when_what_it_says_changed() -> None:
    """A status restating the pose (10 a second while driving) words nothing (issue 28: the GTK
    thread's cost while following); a material change still says the new words at once."""
    from rtmu.model.observables import RobotModel
    from rtmu.ui import map_words
    from rtmu.ui.map_words import MapDescription

    model = RobotModel()
    model.connection.set(CONNECTED)
    model.robot.set(robot())
    said: list[str] = []
    worded = [0]
    real = map_words.map_description

    def counting(*args: object) -> str:
        worded[0] += 1
        return real(*args)  # type: ignore[arg-type]

    map_words.map_description = counting  # type: ignore[assignment]
    try:
        words = MapDescription(model, said.append)
        for step in range(10):  # a few centimetres and a degree each, readings timed anew
            model.robot.set(robot(x=2000.0 + 3 * step, th=0.5 * step, numbers_at=2.0 + step))
        assert worded[0] == 1 and said == [words.text]
        model.robot.set(robot(x=2000.0, th=0.0, battery_v=11.4, numbers_at=20.0))
        assert worded[0] == 2 and "low" in said[-1]
        words.close()
    finally:
        map_words.map_description = real  # type: ignore[assignment]

"""The recorder keeps the server's drawing list and what is shown, not every sample's points."""

from __future__ import annotations

from rtmu.recorder.convert import Converter
from rtmu.values.state import DrawingLayer, DrawingsChanged, DrawingsState


def _state(points: tuple[tuple[int, int], ...], shown: bool = True) -> DrawingsChanged:
    laser = DrawingLayer("sim_lms2xx_1Current", "polyDots", True, 0x0000FF, 80, 75, 200, shown, True, points)
    return DrawingsChanged(DrawingsState((laser,), offered=True))


def test_new_samples_write_nothing_and_a_switch_writes_the_list_once() -> None:
    c = Converter()
    ((topic, first),) = c.change(_state(((1, 2), (3, 4))), 0)
    assert topic == "/rtmu/state/drawings"
    assert first["layers"][0]["points"] == 2 and first["layers"][0]["name"] == "sim_lms2xx_1Current"
    assert c.change(_state(((5, 6), (7, 8), (9, 9))), 1) == []  # only new points: nothing written
    ((_, hidden),) = c.change(_state((), shown=False), 2)
    assert hidden["layers"][0]["shown"] is False and hidden["layers"][0]["points"] == 0

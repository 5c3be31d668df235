"""Pinch zoom on the map: the zoom follows the fingers, stays in 10 %…400 %, and the pinch centre stays put.

Why not a real gesture: Xvfb has no touch devices and xdotool cannot make touch
events, so no real two-finger pinch can reach the window here. Instead the
test drives the map view's own ``Gtk.GestureZoom`` handlers in the order GTK
calls them (``begin`` → ``scale-changed`` … → ``end``) on a real MapView in the
real window connected to the simulator. The wiring itself is checked by
emitting those signals on the real gesture controller of the widget; to give
the handlers touch points, a small stand-in answers ``get_scale_delta`` and
``get_bounding_box_center`` as GTK's gesture would with two fingers down.
"""

from __future__ import annotations

import math

import gi
import pytest

from rtmu.ui.viewport import ZOOM_MAX, ZOOM_MIN
from simulators import simulator

from .harness import OFFICE_MAP, Gui, idle

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402


class TwoFingers:
    """What GTK's GestureZoom reports while two touch points are down: the scale and their centre."""

    def __init__(self, centre: tuple[float, float]) -> None:
        self.centre = centre
        self.scale = 1.0

    def get_scale_delta(self) -> float:
        return self.scale

    def get_bounding_box_center(self) -> tuple[bool, float, float]:
        return True, *self.centre


sim = simulator(map_path=OFFICE_MAP, seed=1)


@pytest.fixture
def gui(gui: Gui) -> Gui:
    """The window of tests/gui/conftest.py with Follow off: with it on, the robot (not the fingers) is the
    zoom's centre."""
    gui.stage.set_follow(False)
    return gui


def pinch(stage, fingers: TwoFingers, *scales: float, end: bool = True) -> None:  # type: ignore[no-untyped-def]
    """One pinch as GTK reports it: begin, a scale-changed per scale (each from the pinch's start), end."""
    stage._pinch_begin(fingers, None)
    for scale in scales:
        fingers.scale = scale
        stage._pinch_changed(fingers, fingers.get_scale_delta())
    if end:
        stage._pinch_end(fingers, None)
    idle(0.05)


def world_under(stage, point: tuple[float, float]) -> tuple[float, float]:  # type: ignore[no-untyped-def]
    return stage.viewport.to_world(*point)


def stays_at(stage, world: tuple[float, float], point: tuple[float, float], px: float = 1.0) -> bool:  # type: ignore[no-untyped-def]
    """The world point is drawn at ``point``, within a pixel (the view's origin is rounded to pixels)."""
    return math.dist(stage.viewport.to_screen(*world), point) <= px


def test_the_map_view_listens_to_a_real_zoom_gesture(gui: Gui) -> None:
    """The real GestureZoom on the widget reaches the handlers (no touch points: zoom about the middle)."""
    stage = gui.stage
    stage.set_zoom(1.0)
    gestures = [c for c in stage.observe_controllers() if isinstance(c, Gtk.GestureZoom)]
    assert len(gestures) == 1, "the map view has one pinch gesture"
    gesture = gestures[0]
    middle = (stage.viewport.width / 2, stage.viewport.height / 2)
    before = world_under(stage, middle)
    gesture.emit("begin", None)
    gesture.emit("scale-changed", 2.0)
    assert stage.viewport.zoom == pytest.approx(2.0)
    gesture.emit("end", None)
    assert stage.viewport.zoom == pytest.approx(2.0)
    assert gui.operator.view.value.zoom == pytest.approx(2.0), "the end of the pinch is remembered"
    assert stays_at(stage, before, middle)
    gui.shot("pinched-200")


def test_a_pinch_zooms_by_its_factor_about_the_fingers(gui: Gui) -> None:
    stage = gui.stage
    stage.set_zoom(1.0)
    fingers = TwoFingers((120.0, 90.0))
    held = world_under(stage, fingers.centre)
    pinch(stage, fingers, 1.2, 1.4, 1.5, end=False)
    assert stage.viewport.zoom == pytest.approx(1.5), "the zoom follows the latest scale from the start"
    assert stays_at(stage, held, fingers.centre), "the point between the fingers stays put"
    stage._pinch_end(fingers, None)
    assert stage.viewport.zoom == pytest.approx(1.5)
    assert stays_at(stage, held, fingers.centre)
    assert gui.operator.view.value.zoom == pytest.approx(1.5)
    gui.shot("pinched-150")

    fingers = TwoFingers((stage.viewport.width - 80.0, stage.viewport.height - 60.0))
    held = world_under(stage, fingers.centre)
    pinch(stage, fingers, 0.7)
    assert stage.viewport.zoom == pytest.approx(1.0), "1.5 × 0.7 = 1.05 ends on the 100 % stop"
    assert stays_at(stage, held, fingers.centre), "ending on a stop keeps the fingers' point"
    assert not stage.fitted
    gui.shot("pinched-100")


def test_a_pinch_is_held_to_10_to_400_percent(gui: Gui) -> None:
    stage = gui.stage
    stage.set_zoom(1.0)
    fingers = TwoFingers((200.0, 150.0))
    pinch(stage, fingers, 3.0, 10.0, end=False)
    assert stage.viewport.zoom == pytest.approx(ZOOM_MAX)
    stage._pinch_end(fingers, None)
    assert stage.viewport.zoom == pytest.approx(ZOOM_MAX)
    gui.shot("pinched-max")

    stage.set_zoom(1.0)
    held = world_under(stage, fingers.centre)
    zooms: list[float] = []
    stage._pinch_begin(fingers, None)
    for scale in (0.5, 0.2, 0.05, 0.01):
        fingers.scale = scale
        stage._pinch_changed(fingers, scale)
        zooms.append(stage.viewport.zoom)
    assert min(zooms) == pytest.approx(ZOOM_MIN), f"not below 10 % while pinching: {zooms}"
    stage._pinch_end(fingers, None)
    assert stage.viewport.zoom == pytest.approx(ZOOM_MIN)
    assert stays_at(stage, held, fingers.centre)
    idle(0.05)
    gui.shot("pinched-min")


def test_a_pinch_from_below_10_percent_never_jumps_in(gui: Gui) -> None:
    """ "Fit map" may be below 10 % for a big building; pinching out there must not zoom in to 10 %."""
    stage = gui.stage
    stage.set_zoom(0.05)
    assert stage.viewport.zoom == pytest.approx(0.05)
    fingers = TwoFingers((150.0, 100.0))
    pinch(stage, fingers, 0.5)
    assert stage.viewport.zoom == pytest.approx(0.05), "pinching out from below 10 % stays where it was"
    pinch(stage, fingers, 1.02)
    assert stage.viewport.zoom <= 0.1 + 1e-9, "a tiny pinch in does not leap past 10 %"
    pinch(stage, fingers, 3.0)
    assert stage.viewport.zoom == pytest.approx(0.15)
    gui.shot("pinched-from-fit")

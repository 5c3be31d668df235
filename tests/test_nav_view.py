"""The window's navigation words and drawing without a window: ``ui.nav_text`` and ``ui.nav_draw``.

The sentences are what the motion pill, the toolbar and the link banner say; the frame is drawn
by the same function as the window's (``frame.draw_frame``), so a path that is not in these pixels
is not on the operator's screen either.
"""

from __future__ import annotations

import cairo
import numpy as np

from rtmu.client.nav_status import LOST
from rtmu.model.observables import NavOutcome, NavState
from rtmu.ui import overlays
from rtmu.ui.frame import Scene, draw_frame
from rtmu.ui.nav_draw import PATH_RGB, Marker, MarkerKind
from rtmu.ui.nav_text import going_text, link_lost_note, loc_level, loc_text, motion_text, outcome_status
from rtmu.ui.viewport import Viewport

GOING = NavState(navigating=True, target="Lab B", remaining_mm=12_420.0)


def test_localization_levels_and_words() -> None:
    assert loc_level(None, None) is None and loc_text(None, None) == ""
    assert (loc_level("Good", 0.95), loc_text("Good", 0.95)) == ("good", "Good 95 %")
    assert loc_level("Good", 0.3) == "poor", "a Good state with a low score is poor"
    assert loc_level("Initializing", 0.0) == "poor"
    assert (loc_level("Lost", 0.08), loc_text("Lost", 0.08)) == ("lost", "Lost 8 %")


def test_motion_says_autonomous_or_held_and_nothing_without_a_link() -> None:
    assert going_text(GOING) == "Going to Lab B — 12.4 m left"
    assert going_text(NavState(navigating=True, target="home")) == "Going home"
    assert going_text(NavState(navigating=True, target="point")) == "Going to the point"
    kind, lines = motion_text(GOING, held=True, link_up=True)
    assert (kind, lines) == (
        "autonomous",
        ("Navigating (autonomous)", "To Lab B", "12.4 m left · Space or STOP cancels"),
    )
    assert motion_text(NavState(), held=True, link_up=True)[0] == "held"
    assert motion_text(NavState(), held=True, link_up=True)[1][0] == "Driving (held keys)"
    dpad = motion_text(NavState(), held=True, link_up=True, by="dpad")
    assert dpad == ("held", ("Driving (D-pad held)", "Let go to stop")), "a D-pad drive is no held key"
    assert motion_text(NavState(), held=False, link_up=True) == ("", ())
    assert motion_text(GOING, held=False, link_up=False) == ("", ()), "the link banner says it then"
    assert (
        link_lost_note(GOING) == " The robot is navigating on its own (going to Lab B); STOP stays available."
    )
    assert link_lost_note(NavState()) == ""


def test_outcome_status_adds_the_reason_once() -> None:
    failed = NavState(outcome=NavOutcome.FAILED, outcome_text="Failed to get to Lab B", reason="path blocked")
    assert outcome_status(failed) == "Failed to get to Lab B because path blocked"
    said = NavState(
        outcome=NavOutcome.FAILED, outcome_text="Failed to get to X (path blocked)", reason="path blocked"
    )
    assert outcome_status(said) == "Failed to get to X (path blocked)"
    assert outcome_status(NavState()) == ""


def test_outcome_status_says_rtmus_own_reason_in_german_and_the_servers_words_as_sent(german: None) -> None:
    lost = NavState(outcome=NavOutcome.FAILED, outcome_text="Failed to get to Lab B", reason=LOST)
    assert outcome_status(lost) == "Failed to get to Lab B (Grund: der Roboter hat seine Position verloren)"
    blocked = NavState(outcome=NavOutcome.FAILED, outcome_text="Failed to get to Lab B", reason="blocked")
    assert outcome_status(blocked) == "Failed to get to Lab B (Grund: blocked)"


def _render(scene: Scene, vp: Viewport) -> np.ndarray:
    surface = cairo.ImageSurface(cairo.FORMAT_RGB24, vp.width, vp.height)
    draw_frame(cairo.Context(surface), vp, scene)
    surface.flush()
    data = np.ndarray((vp.height, surface.get_stride() // 4), np.uint32, surface.get_data())[:, : vp.width]
    return np.stack([(data >> 16) & 0xFF, (data >> 8) & 0xFF, data & 0xFF], axis=-1).astype(int)


def _teal(pixels: np.ndarray, x: float, y: float) -> bool:
    want = np.array([round(c * 255) for c in PATH_RGB])
    patch = pixels[round(y) - 2 : round(y) + 3, round(x) - 2 : round(x) + 3]
    return bool((np.abs(patch - want).sum(axis=2) < 40).any())


def test_the_path_runs_from_the_robot_through_its_corners() -> None:
    vp = Viewport(400, 300, 1.0, 0.0, 0.0)
    path = ((1000, 0), (1000, 1000))
    scene = Scene(labels=overlays.LabelCache(), robot=(-1500.0, 0.0, 0.0), path=path)
    pixels = _render(scene, vp)
    for wx, wy in ((-500, 0), (500, 0), (1000, 500)):  # robot → first corner, then up to the goal
        assert _teal(pixels, *vp.to_screen(wx, wy)), (wx, wy)
    assert not _teal(pixels, *vp.to_screen(0, 800)), "nothing off the path"
    without = _render(Scene(labels=scene.labels, robot=scene.robot), vp)
    assert not _teal(without, *vp.to_screen(500, 0)), "control: no path, no teal"


def test_a_goal_ring_and_a_picked_target_with_its_heading() -> None:
    vp = Viewport(400, 300, 1.0, 0.0, 0.0)
    labels = overlays.LabelCache()
    pixels = _render(Scene(labels=labels, goal=(0.0, 0.0)), vp)
    assert _teal(pixels, 200 + 15, 150) and not _teal(pixels, 200, 150), "a ring, hollow in the middle"
    target = Marker(MarkerKind.GOTO, 0.0, 0.0, 90.0)
    pixels = _render(Scene(labels=labels, marker=target), vp)
    assert _teal(pixels, 200, 150 - 25), "the heading arrow points up the map (90°)"
    assert not _teal(pixels, 200 + 25, 150)

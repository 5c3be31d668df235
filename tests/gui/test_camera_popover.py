"""The camera bar's gear popover (frame rate, JPEG quality) is readable: dark under its white words,
as the bar it opens from (issue 21: it was white text on white). A real click opens it; its pixels
are looked at."""

from __future__ import annotations

import numpy as np
from PIL import Image

from rtmu.ui.live_video import FPS_CHOICES, QUALITY_CHOICES
from simulators import simulator

from .harness import OFFICE_MAP, Gui, pump

sim = simulator(map_path=OFFICE_MAP, camera=True, seed=1)


def test_the_gear_popover_is_dark_with_light_words(gui: Gui) -> None:
    window = gui.window
    gui.key("Escape")
    pump(lambda: window.stack.get_visible_child_name() == "camera", 5, "the camera page")
    controls = window.camera_page.live
    gui.click(controls.settings_button)
    popover = controls.settings_button.get_popover()
    pump(lambda: popover.get_mapped() and popover.get_width() > 0, 3, "the gear popover")
    path = gui.screen_shot("gear-popover")  # a popover is a surface of its own: the screen's pixels
    x, y, _w, _h = gui.screen_rect(popover)
    inner = popover.get_child()
    ok, box = inner.compute_bounds(popover)
    assert ok
    left, top = x + round(box.get_x()), y + round(box.get_y())
    with Image.open(path) as img:
        crop = img.crop((left, top, left + round(box.get_width()), top + round(box.get_height())))
        grey = np.asarray(crop.convert("L")).astype(int)
    assert grey.mean() < 110, f"a light popover under the bar's white words (mean {grey.mean():.0f})"
    assert (grey > 200).sum() > 30, "no light words on it"
    # The drop-downs are made as the gear first opens: what they choose is what the next request asks.
    assert controls.fps is not None and controls.quality is not None
    assert controls.target_fps() == FPS_CHOICES[controls.fps.get_selected()]
    controls.fps.set_selected(0)
    controls.quality.set_selected(len(QUALITY_CHOICES) - 1)
    assert controls.target_fps() == FPS_CHOICES[0]
    assert controls.target_quality() == int(QUALITY_CHOICES[-1])
    popover.popdown()
    gui.click(controls.settings_button)  # opened again: the same drop-downs, the choice kept
    pump(lambda: popover.get_mapped(), 3, "the gear popover again")
    assert controls.fps.get_selected() == 0 and controls.target_fps() == FPS_CHOICES[0]
    popover.popdown()
    gui.key("space")  # Space still stops from the camera page
    pump(lambda: window.stack.get_visible_child_name() == "camera", 3, "the page kept")


def test_the_camera_page_shows_the_navigation_pill(gui: Gui) -> None:
    """Looking at the camera never hides that the robot navigates (and Space still ends it)."""
    window = gui.window
    window.goals_panel.choose("Corridor End")
    pump(lambda: window.motion.kind == "autonomous", 10, "the navigation")
    gui.key("Escape")  # looking: the navigation goes on
    pump(lambda: window.camera_page.showing, 5, "the camera page")
    pill = window.camera_page.motion
    pump(lambda: pill.get_mapped() and pill.kind == "autonomous", 3, "the pill on the camera page")
    assert pill.text.startswith("Navigating (autonomous) · To Corridor End"), pill.text
    gui.shot("camera-page-navigating")
    gui.key("space")
    pump(lambda: not gui.model.navigation.value.navigating, 5, "Space to end the navigation")
    pump(lambda: not pill.get_visible(), 3, "the pill to go")

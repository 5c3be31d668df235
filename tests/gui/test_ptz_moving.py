"""The camera head's label while the head turns, and on a phone (issue 21, camera page).

The simulated head turns at the VC-C4's speeds (90°/s of pan), so a reading taken right after a
click is mid-turn. The label must say the head is moving (and where to, for Home) until the
server's reading settles, then the settled position — never a mid-turn reading as if the head had
stopped there. Every text the label shows is recorded (``notify::label``), so what is checked does
not depend on when the machine gets round to drawing. On a 360×720 phone the position sits on a
line of its own above the buttons and is shown whole (it was cut to "Ca…"). Space and STOP stop the
robot on the camera page in each case.
"""

from __future__ import annotations

from collections.abc import Iterator

import gi
import pytest

from rtmu.sim import SimConfig, SimThread

from .harness import OFFICE_MAP, Gui, idle, pump
from .test_handheld_window import clipped_widgets
from .test_handheld_window import phone as phone  # the fixture: a window on a 360×720 screen
from .test_phone_wm import space_and_stop_stop

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

SETTLED_HOME = "Camera: pan +0°  tilt +0°  zoom 0 %"


@pytest.fixture(scope="module")
def sim() -> Iterator[SimThread]:
    with SimThread(SimConfig(port=0, map_path=OFFICE_MAP, camera=True, seed=1)) as s:
        yield s


def set_head(sim: SimThread, pan: float, tilt: float = 0.0, zoom: float = 0.0) -> None:
    """Someone else has turned the head (at once, no goal left)."""
    assert sim.server is not None
    head = sim.server.world.camera.ptz

    def put() -> None:
        head.pan, head.tilt, head.zoom, head.goal = pan, tilt, zoom, None

    sim.call(put)


def camera_page(gui: Gui) -> None:
    window = gui.window
    gui.key("Escape")
    pump(lambda: window.stack.get_visible_child_name() == "camera", 5, "the camera page")
    pump(lambda: window.ptz.buttons["ptz_home"].get_sensitive(), 10, "the PTZ controls")


class LabelLog:
    """Every text the PTZ label shows from now on."""

    def __init__(self, label: Gtk.Label) -> None:
        self.texts: list[str] = [label.get_text()]
        self._label = label
        self._handler = label.connect("notify::label", lambda lab, _p: self.texts.append(lab.get_text()))

    def close(self) -> None:
        self._label.disconnect(self._handler)


def assert_no_mid_turn_reading(texts: list[str], settled: str) -> None:
    """After the click: only "moving" texts, then the settled one (the last)."""
    assert any("moving" in t for t in texts), texts
    assert texts[-1] == settled, texts
    for text in texts:
        assert "moving" in text or text == settled, (
            f"a reading shown as settled mid-turn: {text!r} in {texts}"
        )


def test_the_label_says_moving_until_the_head_settles(gui: Gui, sim: SimThread) -> None:
    window = gui.window
    ptz = window.ptz
    set_head(sim, 90.0)
    camera_page(gui)
    pump(lambda: ptz.label.get_text() == "Camera: pan +90°  tilt +0°  zoom 0 %", 8, "the head read at +90°")

    log = LabelLog(ptz.label)
    try:
        gui.click(ptz.buttons["ptz_home"])  # 90° back to straight ahead: a second of turning
        said = lambda: any("moving to pan +0°" in t for t in log.texts)  # noqa: E731 (a slow machine may have settled)
        pump(said, 5, "the label to say the head moves")
        gui.shot("moving-home")
        pump(lambda: ptz.label.get_text() == SETTLED_HOME, 15, "the settled position")
    finally:
        log.close()
    after_home = log.texts[log.texts.index(next(t for t in log.texts if "moving" in t)) :]
    assert_no_mid_turn_reading(after_home, SETTLED_HOME)
    gui.shot("settled-home")

    log = LabelLog(ptz.label)
    try:
        gui.click(ptz.buttons["ptz_left"])  # a turn by 10°: "moving…", then the new position
        pump(lambda: ptz.label.get_text() == "Camera: pan -10°  tilt +0°  zoom 0 %", 15, "the turn to settle")
    finally:
        log.close()
    assert_no_mid_turn_reading(log.texts[1:], "Camera: pan -10°  tilt +0°  zoom 0 %")
    space_and_stop_stop(gui, sim, window.stop_button, "on the camera page after a head move")


def test_the_head_position_fits_a_phone(phone: tuple[Gui, SimThread]) -> None:
    gui, sim = phone
    window = gui.window
    ptz = window.ptz
    pump(lambda: window.handheld.layout.narrow, 5, "the phone layout")
    set_head(sim, -45.0, 20.0, 30.0)
    camera_page(gui)
    text = "Camera: pan -45°  tilt +20°  zoom 30 %"
    pump(lambda: ptz.label.get_text() == text, 8, "the head's position")
    idle(0.5)
    layout = ptz.label.get_layout()
    assert not layout.is_ellipsized(), f"the position is cut: {ptz.label.get_text()!r}"
    assert all(b.get_mapped() for b in ptz.buttons.values())
    assert clipped_widgets(window) == []
    gui.shot("phone-position")
    moving = "Camera: moving to pan +0°  tilt +0°  zoom 30 %…"  # Home keeps the zoom
    ptz.label.set_text(moving)  # the longest text it shows here, laid out whatever the timing
    idle(0.2)
    assert not ptz.label.get_layout().is_ellipsized(), f"cut while moving: {ptz.label.get_text()!r}"
    assert clipped_widgets(window) == []
    ptz.label.set_text(text)  # the reading again, so that the move's own "moving" is a change
    log = LabelLog(ptz.label)
    try:
        gui.click(ptz.buttons["ptz_home"])
        pump(lambda: moving in log.texts[1:], 5, "the label to say the head moves")
        gui.shot("phone-moving")
        home = "Camera: pan +0°  tilt +0°  zoom 30 %"
        pump(lambda: ptz.label.get_text() == home, 15, "the settled position")
    finally:
        log.close()
    space_and_stop_stop(gui, sim, window.stop_button, "on the phone's camera page")

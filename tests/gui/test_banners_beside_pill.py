"""At 800×480 the banners share the top row with the navigation pill (issue 21, "Banners that lie").

Before, where the centred banner column would have covered the pill it was pushed down under the
pill, over the map (and, at 800×480, over the robot). Where there is room beside the pill (800×480,
1280×800) the column now sits beside it, on the same row; only a phone (360 px) puts the banners
under the pill. Checked with the robot navigating and two banners up, on a screen of each size
(the window fills it): no banner covers the pill or the robot as drawn (on a phone the column goes
above the D-pad where under the pill it would cover the robot), and beside the pill the first banner
starts above the pill's bottom. Space and STOP still stop the robot.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import gi
import pytest

from rtmu.sim import SimConfig, SimThread

from .harness import OFFICE_MAP, Gui, idle, on_display, pump
from .stop_paths import StopCycle
from .test_dpad_place import Rect, overlap, rect
from .test_phone_wm import space_and_stop_stop

gi.require_version("Gtk", "4.0")
gi.require_version("Graphene", "1.0")
from gi.repository import Graphene  # noqa: E402

LONG = "The server says something long enough to wrap onto a second line of the banner, as servers do"
SHORT = "A second message from the server"


def drawn_banners(gui: Gui) -> list[Rect]:
    """The box of each banner shown (the column may be wider than what it draws), in window terms."""
    out = []
    child = gui.window.banners.get_first_child()
    while child is not None:
        box = child.get_child()  # type: ignore[attr-defined]
        if child.get_child_revealed() and box is not None:  # type: ignore[attr-defined]
            out.append(rect(box, gui.window))
        child = child.get_next_sibling()
    return out


def robot_rect(gui: Gui) -> Rect:
    """The robot as drawn on the map (its body and a margin), in window terms."""
    robot = gui.model.robot.value
    sx, sy = gui.stage.viewport.to_screen(robot.x, robot.y)
    ok, point = gui.stage.compute_point(gui.window, Graphene.Point().init(sx, sy))
    assert ok
    return point.x - 14, point.y - 14, point.x + 14, point.y + 14


def check(gui: Gui, sim: SimThread, label: str, *, beside: bool, robot_clear: bool = True) -> None:
    window = gui.window
    cycle = StopCycle(gui, sim)
    cycle.navigate()
    pump(lambda: window.motion.get_mapped() and window.motion.kind == "autonomous", 10, "the navigation pill")
    for text in (LONG, SHORT):
        window.banners.tell(f"notice:{text}", "warning", text, timeout=None)
    pump(lambda: len(drawn_banners(gui)) == 2, 5, "two banners")
    pill = rect(window.motion, window)
    # The window's once-a-second timer places the column: wait for a layout clear of the pill.
    pump(
        lambda: not any(overlap(b, rect(window.motion, window)) for b in drawn_banners(gui)),
        5,
        "banners off the pill",
    )
    idle(1.2)  # a second placement: it holds (no see-saw)
    pill, banners = rect(window.motion, window), drawn_banners(gui)
    gui.shot(label)
    assert not [b for b in banners if overlap(b, pill)], f"{label}: banners {banners} cover the pill {pill}"
    robot = robot_rect(gui)
    assert not robot_clear or not [b for b in banners if overlap(b, robot)], (
        f"{label}: banners {banners} cover the robot {robot}"
    )
    first = min(banners, key=lambda b: b[1])
    if beside:
        assert first[1] < pill[3], f"{label}: the banners {banners} are pushed under the pill {pill}"
        assert first[0] >= pill[2], f"{label}: the banners {banners} are not beside the pill {pill}"
    cycle.space_stops(f"with banners beside the pill ({label})")
    cycle.navigate()
    before = cycle.stops()
    gui.click(window.stop_button)
    pump(lambda: cycle.stops() > before, 5, f"STOP to stop the robot ({label})")


@pytest.fixture
def sim() -> Iterator[SimThread]:
    with SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=1)) as s:
        yield s


def test_banners_beside_the_pill_at_800x480(screenshots: Path, small_screen: str, sim: SimThread) -> None:
    with on_display(small_screen):
        gui = Gui.start(screenshots, "banners-800x480", "127.0.0.1", sim.port)
        try:
            check(gui, sim, "800x480", beside=True)
        finally:
            gui.close()


def test_banners_beside_the_pill_at_1280x800(gui: Gui, sim: SimThread) -> None:
    gui.window.set_default_size(1280, 800)
    pump(lambda: gui.window.get_width() >= 1200, 5, "the window at 1280 px")
    check(gui, sim, "1280x800", beside=False)


def test_banners_under_the_pill_on_a_phone(screenshots: Path, phone_screen: str, sim: SimThread) -> None:
    with on_display(phone_screen):
        gui = Gui.start(screenshots, "banners-360x720", "127.0.0.1", sim.port)
        try:
            # A phone's Fit shows the whole map in a band that banners under the pill would cover:
            # where the robot is under them, they go above the thumb's D-pad instead.
            check(gui, sim, "360x720", beside=False)
            space_and_stop_stop(gui, sim, gui.window.stop_button, "on the phone with banners")
        finally:
            gui.close()

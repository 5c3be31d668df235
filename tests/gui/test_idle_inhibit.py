"""While the robot moves, the desktop may not lock the screen or suspend, and the window says so.

The real window drives the real simulator with a real held key; the desktop's side is
``fake_desktop`` on the test's session bus (GTK asks ``org.gnome.SessionManager``, which
Xvfb's session lacks). What is checked: nothing is asked while the robot stands; a held drive asks
for idle + suspend inhibition with the reason, once, and the motion pill says "Screen kept on";
after the robot has rested it is let go with the same cookie, and the note goes.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from rtmu.sim import SimThread
from rtmu.ui import idle_inhibit
from simulators import simulator

from .desktop_side import Desktop, fake_desktop
from .harness import OFFICE_MAP, Gui, idle, pump

HERE = Path(__file__).parent
IDLE_AND_SUSPEND = 8 | 4  # GtkApplicationInhibitFlags IDLE | SUSPEND


@pytest.fixture
def desktop() -> Iterator[Desktop]:
    with fake_desktop() as d:
        yield d


sim = simulator(map_path=OFFICE_MAP, camera=False, seed=1)


def test_a_moving_robot_keeps_the_screen_on_and_the_window_says_so(
    desktop: Desktop, gui: Gui, sim: SimThread, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(idle_inhibit, "RELEASE_AFTER", 1.0)
    gui.wait_connected()
    idle(1.0)
    assert desktop.of("Inhibit", "Uninhibit") == [], "asked while the robot stood still"
    gui.focus()
    gui.keydown("Up")
    try:
        pump(lambda: bool(desktop.of("Inhibit", "Uninhibit")), 10, "the inhibition")
        (call,) = desktop.of("Inhibit", "Uninhibit")
        assert call["call"] == "Inhibit" and call["flags"] == IDLE_AND_SUSPEND, call
        assert "robot is moving" in call["reason"]
        pump(lambda: "Screen kept on" in gui.window.motion.text, 5, "the note in the motion pill")
        gui.shot("screen-kept-on")
    finally:
        gui.keyup("Up")
    pump(lambda: abs(sim.snapshot().vel) < 1, 15, "the robot to stop")
    pump(lambda: len(desktop.of("Inhibit", "Uninhibit")) == 2, 15, "the inhibition to be let go")
    released = desktop.of("Inhibit", "Uninhibit")[1]
    assert released == {"call": "Uninhibit", "cookie": call["cookie"]}
    assert "Screen kept on" not in gui.window.motion.text

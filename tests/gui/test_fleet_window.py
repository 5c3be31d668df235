"""The window is a fleet of one, but every way out stops every robot of the fleet.

A second robot session (its own simulator, its own network thread) is added to the
running application beside the one the window shows; both drive — the window's by a
real held key, the other by its controller — and one real Ctrl+Q, or closing the
window, stops both before either server's 2 s watchdog.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from gi.repository import GLib

from rtmu.client.session import SessionConfig
from rtmu.fleet.sessions import RobotSession
from rtmu.model.observables import Phase
from rtmu.settings.store import Profile
from rtmu.sim import SimThread
from simulators import running

from .harness import OFFICE_MAP, Gui, pump


def mode(sim: SimThread) -> str:
    return str(sim.call(lambda: sim.server.robot.mode_name))


def watchdog_stops(sim: SimThread) -> int:
    return int(sim.call(lambda: sim.server.robot.watchdog_stops))


@pytest.fixture
def sims() -> Iterator[tuple[SimThread, SimThread]]:
    with (
        running(map_path=OFFICE_MAP, seed=1) as shown,
        running(map_path=OFFICE_MAP, seed=2) as other,
    ):
        yield shown, other


def drive_both(gui: Gui, other: RobotSession, sims: tuple[SimThread, SimThread]) -> None:
    other.controller.press("forward")
    GLib.timeout_add(100, lambda: (other.controller.tick() or True) and not other.closed)
    gui.keydown("Up")
    pump(lambda: all(mode(sim) == "ratioDrive" for sim in sims), 5, "both robots to drive")
    pump(lambda: all(sim.snapshot().vel > 0 for sim in sims), 5, "both robots to move")


def open_second(gui: Gui, sim: SimThread) -> RobotSession:
    profile = Profile("second", host="127.0.0.1", port=sim.port)
    other = gui.app.fleet.open(
        post=GLib.idle_add, config=SessionConfig(fetch_map=False), profile=profile, select=False
    )
    other.controller.connect()
    pump(lambda: other.state.connection.value.phase is Phase.CONNECTED, 10, "the second robot to connect")
    assert gui.app.session is not other, "the window still shows its own robot"
    return other


@pytest.mark.parametrize("way_out", ["ctrl+q", "close the window"])
def test_every_way_out_stops_every_robot(
    way_out: str, screenshots: Path, sims: tuple[SimThread, SimThread]
) -> None:
    shown, other_sim = sims
    gui = Gui.start(screenshots, f"fleet-{way_out.replace(' ', '-')}", "127.0.0.1", shown.port)
    try:
        other = open_second(gui, other_sim)
        assert len(gui.app.fleet) == 2
        drive_both(gui, other, sims)
        gui.shot("both-driving")
        before = [watchdog_stops(sim) for sim in sims]
        if way_out == "ctrl+q":
            gui.key("ctrl+q")
        else:
            gui.window.close()
        # Ours, not ARIA's 2 s watchdog: told by the watchdogs' own counts, not by a clock.
        pump(lambda: all(mode(sim) == "stop" for sim in sims), 3, "every robot of the fleet to stop")
        assert [watchdog_stops(sim) for sim in sims] == before, "a watchdog stopped a robot, not us"
    finally:
        gui.keyup("Up")
        gui.close()
    assert other.closed and not other.runner._thread.is_alive(), "the second session outlived the app"

"""A fleet bigger than the window connects to: robots listed, connected when selected, and a huge list.

* a fleet profile that keeps 2 of its 3 robots connected: the third is listed as "not connected",
  a click on its row connects it (its simulator sees the login) and the robot used least recently
  is let go — quietly: it was idle, so it is sent no stop;
* ARIA's central server listing 1 000 robots (``ListingCentral``, at two simulators' ports): the
  window connects to 20 of them at most, STOP still reaches the selected robot while the list
  pours in, and SIGTERM ends it (every robot stopped, every connection closed) within a generous
  bound — it used to ignore SIGTERM for 15 s. Speed is measured in ``bench/bench_fleet_scale.py``.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from rtmu.fleet.sessions import RobotSession
from rtmu.guardian.child import WARM_MAX
from rtmu.settings.store import DirectRobot
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.central_listing import ListingCentralThread
from rtmu.sim.multi import SimFleetThreads, fleet_configs
from rtmu.ui.fleet_bind import FleetBinding
from rtmu.ui.options import GuiOptions
from rtmu.ui.robot_list import NOT_CONNECTED

from .harness import OFFICE_MAP, Gui, pump, scratch_dir
from .process import PATIENCE, screenshot, wait, xdotool

BUDGET = 20
"""A fleet window's robots connected at once by default (``connect_at_most``)."""


@pytest.fixture
def sims() -> Iterator[list[SimThread]]:
    with SimFleetThreads(fleet_configs(SimConfig(port=0, map_path=OFFICE_MAP), 3)) as fleet:
        yield fleet.sims


def logins(sim: SimThread) -> int:
    return len(sim.call(lambda: list(sim.server.sessions)))


def subscribed(sim: SimThread) -> int:
    """Logins whose session is set up: they asked for their status (the guardian's never does)."""
    return sum(sim.call(lambda: [bool(c.subscriptions) for c in sim.server.sessions]))  # type: ignore[union-attr]


def stop_requests(*sims: SimThread) -> int:
    return sum(len(sim.call(lambda sim=sim: list(sim.server.stop_log))) for sim in sims)


def binding(gui: Gui) -> FleetBinding:
    assert gui.app.fleet_binding is not None
    return gui.app.fleet_binding


def named(gui: Gui, name: str) -> RobotSession:
    found = gui.app.fleet.named(name)
    assert found is not None, name
    return found


def test_a_listed_robot_says_it_is_not_connected_and_connects_when_its_row_is_clicked(
    screenshots: Path, sims: list[SimThread]
) -> None:
    robots = tuple(DirectRobot(f"robot{i + 1}", "127.0.0.1", sim.port) for i, sim in enumerate(sims))
    options = GuiOptions(
        fleet=robots,
        connect_at_most=2,
        settings_path=scratch_dir("settings-") / "settings.toml",
        persist=False,
    )
    gui = Gui.open(options, screenshots, "fleet-budget")
    try:
        fleet = gui.app.fleet
        pump(lambda: [s.name for s in fleet] == ["robot1", "robot2"], 10, "two robots connected")
        pump(lambda: all(s.state.robot.value.numbers_at is not None for s in fleet), 15, "their status")
        assert [e.name for e in fleet.listed.value] == ["robot1", "robot2", "robot3"]
        assert logins(sims[2]) == 0, "the robot beyond the budget was connected"
        rows = binding(gui).robot_list
        pump(lambda: rows.row_named("robot3") is not None, 5, "robot3's row")
        row = rows.row_named("robot3")
        assert row is not None
        assert row.link.get_text() == NOT_CONNECTED and row.has_css_class("robot-stale")
        gui.shot("robot3-listed")

        gui.click(row)
        pump(lambda: fleet.selected.value is not None and fleet.selected.value.name == "robot3", 5, "robot3")
        third = named(gui, "robot3")
        pump(lambda: third.state.connection.value.connected, 15, "robot3 to connect")
        assert logins(sims[2]) >= 1
        # Three would be over the budget: robot2 (never selected, idle) is let go, without a stop.
        pump(lambda: fleet.named("robot2") is None, 5, "robot2 to be let go")
        pump(lambda: logins(sims[1]) == 0, 10, "robot2's connection to close")
        assert sims[1].call(lambda: list(sims[1].server.stop_log)) == [], "an idle robot let go was stopped"
        assert fleet.named("robot1") is not None
        pump(lambda: third.state.robot.value.numbers_at is not None, 10, "robot3's status")
        gui.wait_armed(third)
        pump(lambda: gui.window.subtitle_label.get_text().startswith("robot3"), 5, "the window on robot3")
        pump(lambda: (r := rows.row_named("robot2")) is not None and r.link.get_text() == NOT_CONNECTED, 5,
             "robot2's row to say it is not connected")  # fmt: skip
        gui.keydown("Up")
        pump(lambda: sims[2].snapshot().vel > 0, 5, "robot3 to drive")
        gui.keyup("Up")
        gui.shot("robot3-connected")
    finally:
        gui.keyup("Up")
        gui.close()


def test_a_central_server_listing_1000_robots_gets_20_connections_stop_still_works_and_sigterm_ends_it(
    tmp_path: Path, screenshots: Path
) -> None:
    with (
        SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=1, camera=False)) as one,
        SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=2, camera=False)) as two,
        ListingCentralThread(1000, [one.port, two.port]) as central,
    ):
        env = dict(os.environ, XDG_CONFIG_HOME=str(tmp_path))
        proc = subprocess.Popen(
            [sys.executable, "-m", "rtmu", "--central", f"127.0.0.1:{central.port}"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        most = 0

        def connections() -> int:
            nonlocal most
            now = logins(one) + logins(two)
            most = max(most, now)
            return now

        try:
            found = xdotool("search", "--sync", "--onlyvisible", "--pid", str(proc.pid), "--name", "RTMU")
            window = found.split()[0]
            # 20 robots (at the two simulators, whichever were named first) and the one guardian — with
            # at most WARM_MAX logins it keeps ready for the robots beside the selected one.
            wait(lambda: connections() >= BUDGET + 1, 90, "20 robot connections and the guardian's")
            # A login is not yet a robot the window shows: Space stops a robot once its session is up.
            wait(lambda: subscribed(one) + subscribed(two) >= BUDGET, 60, "the 20 sessions set up")
            xdotool("windowfocus", "--sync", window)
            stops = stop_requests(one, two)
            # STOP, to the robot shown (at one of the two simulators). While the list pours in, the robot
            # shown may still be one that is listed but not yet connected (nothing to stop there), so Space
            # is pressed every 0.5 s until a stop arrives: the window must keep answering keys meanwhile.
            deadline = time.monotonic() + 15 * PATIENCE
            while stop_requests(one, two) == stops:
                assert time.monotonic() < deadline, "no STOP reached the robot shown in time"
                xdotool("key", "space")
                wait_until = time.monotonic() + 0.5
                while stop_requests(one, two) == stops and time.monotonic() < wait_until:
                    time.sleep(0.02)
            end = time.monotonic() + 2.0
            while time.monotonic() < end:  # the rest of the list keeps arriving: no more connections
                connections()
                time.sleep(0.05)
            screenshot(screenshots / "test_fleet_scale-1000-listed.png", window)
            assert BUDGET + 1 <= most <= BUDGET + 1 + WARM_MAX, f"{most} connections at once"
            proc.send_signal(signal.SIGTERM)
            assert proc.wait(60) == 0, proc.stderr.read() if proc.stderr else ""
            wait(lambda: connections() == 0, 15, "every connection to close")
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait(5)

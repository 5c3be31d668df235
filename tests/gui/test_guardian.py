"""The real window, driving with a held Up, then SIGKILLed or SIGSTOPped: its guardian stops the robot.

A killed or frozen process sends nothing: before the guardian only the
simulator's own 2 s watchdog stopped the robot then. Now the simulator must
record a ``stop`` sent by the guardian's connection (its self identifier), and
its watchdog must not have fired. No wall-clock limit here: the figures are in
``bench/bench_safety.py``.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from guardians import guardian_stops, guardians_of, logins
from rtmu.settings.store import DirectRobot, Profile, Settings, save_settings
from rtmu.sim import SimConfig, SimThread

from .harness import OFFICE_MAP
from .process import connect_and_hold_up, subscribed, wait, xdotool


@pytest.mark.parametrize("signum", [signal.SIGKILL, signal.SIGSTOP], ids=["SIGKILL", "SIGSTOP"])
def test_a_killed_or_frozen_window_is_stopped_by_its_guardian(signum: int, tmp_path: Path) -> None:
    with SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=1)) as sim:
        env = dict(os.environ, XDG_CONFIG_HOME=str(tmp_path))
        proc = subprocess.Popen(
            [sys.executable, "-m", "rtmu", "--host", "127.0.0.1", "--port", str(sim.port)],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        held = False
        try:
            connect_and_hold_up(proc, sim)
            held = True
            # The guardian logged in beside the window (two sessions), and has stopped nothing yet.
            wait(lambda: logins(sim) == 2, 10, "the guardian's login")
            assert guardian_stops(sim) == 0
            watchdog = sim.call(lambda: sim.server.robot.watchdog_stops)
            proc.send_signal(signum)
            wait(lambda: guardian_stops(sim) == 1, 20, "a stop from the guardian")
            assert sim.call(lambda: sim.server.robot.mode_name) == "stop"
            assert sim.call(lambda: sim.server.robot.watchdog_stops) == watchdog, "the watchdog fired"
        finally:
            if proc.poll() is None:
                proc.send_signal(signal.SIGCONT)
                proc.kill()
            proc.wait(5)
            if held:  # after the window is gone: X calls can wait on a stopped client
                xdotool("keyup", "Up")
        # With the window gone its guardian leaves too (EOF on its pipe).
        wait(lambda: logins(sim) == 0, 10, "the guardian to log out")


@pytest.mark.parametrize("signum", [signal.SIGKILL, signal.SIGSTOP], ids=["SIGKILL", "SIGSTOP"])
def test_a_fleet_window_killed_or_frozen_is_stopped_by_its_one_guardian_at_the_selected_robot(
    signum: int, tmp_path: Path
) -> None:
    """Two robots, robot2 selected by keyboard and driven: ONE guardian, armed for robot2, stops it."""
    with (
        SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=1)) as one,
        SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=2)) as two,
    ):
        robots = (DirectRobot("robot1", "127.0.0.1", one.port), DirectRobot("robot2", "127.0.0.1", two.port))
        save_settings(
            Settings({"two": Profile("two", robots=robots)}, "two"), tmp_path / "rtmu" / "settings.toml"
        )
        env = dict(os.environ, XDG_CONFIG_HOME=str(tmp_path), XDG_DATA_HOME=str(tmp_path))
        proc = subprocess.Popen(
            [sys.executable, "-m", "rtmu", "--profile", "two"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        held = False
        try:
            window = xdotool("search", "--sync", "--onlyvisible", "--pid", str(proc.pid), "--name", "RTMU")
            window = window.split()[0]
            wait(lambda: subscribed(one) and subscribed(two), 20, "both robots connected")
            xdotool("windowfocus", "--sync", window)
            xdotool("key", "alt+2")  # robot2: the guardian watches it (robot1's login is only kept ready)
            wait(lambda: logins(two) == 2, 15, "the guardian at robot2")
            assert logins(one) == 2  # kept ready for a selection back; never stopped (checked below)
            for _attempt in range(5):  # a press before it is armed is refused: press again
                xdotool("keydown", "Up")
                held = True
                try:
                    wait(lambda: abs(two.snapshot().vel) > 1.0, 2, "robot2 to drive")
                    break
                except AssertionError:
                    xdotool("keyup", "Up")
                    held = False
            assert held, "robot2 never drove"
            assert guardians_of(proc.pid) != [] and len(guardians_of(proc.pid)) == 1, "not ONE guardian"
            watchdog = two.call(lambda: two.server.robot.watchdog_stops)
            # Counted from here: on a busy machine the guardian may already have stopped a drive whose
            # heartbeats came late (then the test pressed again); checked is the stop after the signal.
            before = guardian_stops(two)
            proc.send_signal(signum)
            wait(lambda: guardian_stops(two) > before, 20, "a stop from the guardian at robot2")
            assert two.call(lambda: two.server.robot.watchdog_stops) == watchdog, "the watchdog fired"
            assert guardian_stops(one) == 0 and abs(one.snapshot().vel) < 1.0
        finally:
            if proc.poll() is None:
                proc.send_signal(signal.SIGCONT)
                proc.kill()
            proc.wait(5)
            if held:  # after the window is gone: X calls can wait on a stopped client
                xdotool("keyup", "Up")
        wait(lambda: logins(two) == 0, 10, "the guardian to log out")

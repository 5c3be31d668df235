"""``rtmu --host … --port …`` as a process, driving with a held key, then a signal that would kill it.

Each must end the window like Ctrl+C and kill do: the robot is stopped first (the
simulator switches to its stop mode before its own 2 s watchdog could fire),
then the process exits with status 0. Left to their default, these signals
killed the process and left the robot driving.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from rtmu.sim import SimConfig, SimThread

from .harness import OFFICE_MAP
from .process import connect_and_hold_up, screenshot, wait, xdotool

SIGNALS = [signal.SIGHUP, signal.SIGQUIT, signal.SIGUSR1, signal.SIGUSR2, signal.SIGALRM]


@pytest.mark.parametrize("signum", SIGNALS, ids=[signal.Signals(s).name for s in SIGNALS])
def test_a_hangup_or_quit_signal_stops_the_robot_then_exits(
    signum: int, tmp_path: Path, screenshots: Path
) -> None:
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
            window = connect_and_hold_up(proc, sim)
            held = True
            name = signal.Signals(signum).name
            screenshot(screenshots / f"test_signals-{name}-01-driving.png", window)
            watchdog_stops = sim.call(lambda: sim.server.robot.watchdog_stops)
            proc.send_signal(signum)
            # The simulator's stop mode comes only from a "stop" request (its watchdog and a client
            # that vanishes leave the mode as it is), and it must come before the watchdog fired.
            wait(lambda: sim.call(lambda: sim.server.robot.mode_name) == "stop", 5, "an explicit stop")
            assert sim.call(lambda: sim.server.robot.watchdog_stops) == watchdog_stops, "the watchdog fired"
            assert proc.wait(10) == 0, proc.stderr.read() if proc.stderr else ""
        finally:
            if held:
                xdotool("keyup", "Up")
            if proc.poll() is None:
                proc.kill()
                proc.wait(5)

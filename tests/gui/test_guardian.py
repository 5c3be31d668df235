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

from rtmu.guardian.halt import IDENTIFIER
from rtmu.sim import SimConfig, SimThread

from .harness import OFFICE_MAP
from .process import connect_and_hold_up, wait, xdotool


def guardian_stops(sim: SimThread) -> int:
    return sum(1 for _t, _ident, who in sim.call(lambda: list(sim.server.stop_log)) if who == IDENTIFIER)


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
            wait(lambda: len(sim.call(lambda: list(sim.server.sessions))) == 2, 10, "the guardian's login")
            assert guardian_stops(sim) == 0
            watchdog = sim.call(lambda: sim.server.robot.watchdog_stops)
            proc.send_signal(signum)
            wait(lambda: guardian_stops(sim) == 1, 5, "a stop from the guardian")
            assert sim.call(lambda: sim.server.robot.mode_name) == "stop"
            assert sim.call(lambda: sim.server.robot.watchdog_stops) == watchdog, "the watchdog fired"
        finally:
            if held:
                xdotool("keyup", "Up")
            if proc.poll() is None:
                proc.send_signal(signal.SIGCONT)
                proc.kill()
            proc.wait(5)
        # With the window gone its guardian leaves too (EOF on its pipe).
        wait(lambda: not sim.call(lambda: list(sim.server.sessions)), 10, "the guardian to log out")

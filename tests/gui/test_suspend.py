"""Ctrl+Z (SIGTSTP) on ``rtmu`` while a key drives: the robot is stopped before the process freezes.

A stopped process sends nothing, so the stop must be out first: the simulator is in its stop
mode (only an explicit ``stop`` request puts it there) before its own 2 s watchdog fired, and
the process is really stopped ('T'). After SIGCONT the key still held down must not start the
robot again: only a fresh press does.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from rtmu.sim import SimConfig, SimThread

from .harness import OFFICE_MAP
from .process import connect_and_hold_up, screenshot, wait, xdotool


def process_state(pid: int) -> str:
    """The state letter of /proc/PID/stat ('T' = stopped by a signal)."""
    stat = Path(f"/proc/{pid}/stat").read_text()
    return stat.rsplit(")", 1)[1].split()[0]


STOP_READ_GRACE = 1.0
"""How long the simulator may take to read a stop already sent: half its 2 s watchdog."""


def wait_for_stop_mode(sim: SimThread, message: str) -> None:
    """Wait (bounded) until the simulator is in its stop mode, which only a ``stop`` request sets."""
    robot = sim.server.robot
    deadline = time.monotonic() + STOP_READ_GRACE
    while sim.call(lambda: robot.mode_name) != "stop":
        assert time.monotonic() < deadline, message
        time.sleep(0.02)


def test_ctrl_z_stops_the_robot_then_the_process_and_nothing_drives_after_resume(
    tmp_path: Path, screenshots: Path
) -> None:
    with SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=1)) as sim:
        env = dict(os.environ, XDG_CONFIG_HOME=str(tmp_path))
        # Its own process group in our session: a stop signal to an orphaned group would be discarded.
        proc = subprocess.Popen(
            [sys.executable, "-m", "rtmu", "--host", "127.0.0.1", "--port", str(sim.port)],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
            process_group=0,
        )
        held = False
        robot = sim.server.robot

        def drives_received() -> int:
            return int(sim.call(lambda: robot.ratio_drives_received))

        try:
            window = connect_and_hold_up(proc, sim)
            held = True
            watchdog_stops = sim.call(lambda: robot.watchdog_stops)

            proc.send_signal(signal.SIGTSTP)
            wait(lambda: process_state(proc.pid) == "T", 5, "the process to stop")
            # Frozen now, so whatever the simulator still reads left before the freeze; its own
            # thread may not have read it yet. Well inside the watchdog's 2 s, and checked below.
            wait_for_stop_mode(sim, "no explicit stop before the freeze")
            assert sim.call(lambda: robot.watchdog_stops) == watchdog_stops, "the watchdog fired"
            frozen_at = drives_received()

            proc.send_signal(signal.SIGCONT)
            wait(lambda: process_state(proc.pid) != "T", 5, "the process to resume")
            # Up is still held (X repeats it): nothing may drive. The point is that time passes.
            time.sleep(0.6)
            assert drives_received() == frozen_at, "a drive resumed without a fresh press"
            assert sim.call(lambda: robot.mode_name) == "stop"
            assert proc.poll() is None
            screenshot(screenshots / "test_suspend-01-resumed.png", window)

            # A real release, then a fresh press drives again. The operator is at the window: give it
            # the focus back first (a resumed process on a busy X server may not have it yet), and
            # press again if a press was lost — never without a release before it.
            xdotool("windowfocus", "--sync", window)
            for attempt in range(3):
                xdotool("keyup", "Up")
                held = False
                xdotool("keydown", "Up")
                held = True
                try:
                    wait(lambda: drives_received() > frozen_at, 5, "a fresh press to drive again")
                    break
                except AssertionError:
                    if attempt == 2:
                        raise
            # The handler is back after the resume: a second Ctrl+Z stops the robot again first.
            proc.send_signal(signal.SIGTSTP)
            wait(lambda: process_state(proc.pid) == "T", 5, "the process to stop a second time")
            wait_for_stop_mode(sim, "the second suspend did not stop first")
            proc.send_signal(signal.SIGCONT)
            xdotool("keyup", "Up")
            held = False
            proc.send_signal(signal.SIGTERM)
            assert proc.wait(10) == 0, proc.stderr.read() if proc.stderr else ""
            said = (proc.stderr.read() if proc.stderr else "").splitlines()
            said = [line for line in said if "suspended" in line]  # each suspension's stop, once
            assert said == ["rtmu: Stopped: RTMU was suspended (Ctrl+Z). Press again to drive."] * 2, said
        finally:
            if held:
                xdotool("keyup", "Up")
            if proc.poll() is None:
                proc.send_signal(signal.SIGCONT)
                proc.kill()
                proc.wait(5)

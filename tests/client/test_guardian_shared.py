"""The window's ONE guardian: armed for the selected robot before it drives, armed again on a new selection.

A real driving process (``fleet_parent.py``: the window's fleet, controllers and one
:class:`~rtmu.guardian.shared.SharedGuardian`, without GTK) drives real simulators over loopback. The
guardian's own login is held back by a proxy (``FaultProxy``'s ``later_held``), so the window is
connected well before its guardian is: exactly when a freeze used to go uncaught (the robot drove
through it until ARIA's 2 s watchdog). What is checked is what the simulators saw — who stopped the
robot (the guardian's self identifier), that the watchdog did not have to, that no ``ratioDrive`` left
before the guardian was armed — never how many ms anything took (``bench/bench_safety.py`` measures
that).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from guardians import guardian_stops, guardians_of, logins
from linkfaults import FaultProxy
from rtmu.sim import SimThread
from simulators import running

from .uiqueue import eventually

PARENT = Path(__file__).with_name("fleet_parent.py")
HOLD = 1.5
"""Seconds the guardian's login is held back (the window is connected long before)."""


class Parent:
    """The driving process: one line per command, one line per answer."""

    def __init__(self, robots: dict[str, int]) -> None:
        argv = [sys.executable, str(PARENT), *(f"{name}={port}" for name, port in robots.items())]
        self.proc = subprocess.Popen(argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        line = self.answer()
        assert line.startswith("ready "), line
        self.guardian_pid = int(line.split()[1])

    def answer(self) -> str:
        assert self.proc.stdout is not None
        line = self.proc.stdout.readline().strip()
        assert line, f"the driving process ended (exit {self.proc.poll()})"
        return line

    def ask(self, command: str) -> str:
        assert self.proc.stdin is not None
        self.proc.stdin.write(command + "\n")
        self.proc.stdin.flush()
        return self.answer()

    def end(self) -> None:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGCONT)
            self.proc.kill()
        self.proc.wait(10)


@pytest.fixture
def sims() -> Iterator[list[SimThread]]:
    with running(seed=1) as one, running(seed=2) as two:
        yield [one, two]


def drives(sim: SimThread) -> int:
    return int(sim.call(lambda: sim.server.robot.ratio_drives_received))


def driving(sim: SimThread) -> bool:
    return abs(sim.snapshot().vel) > 1.0


def test_a_freeze_soon_after_connecting_is_caught_because_no_key_drives_before_the_guardian_is_armed(
    sims: list[SimThread],
) -> None:
    sim = sims[0]
    with FaultProxy("127.0.0.1", sim.port, later_held=HOLD) as proxy:
        parent = Parent({"robot1": proxy.port})
        try:
            answer = parent.ask("press forward")  # the window is connected; its guardian not yet
            assert answer.startswith("refused") and "arming the guardian for robot1" in answer, answer
            assert parent.ask("release forward") == "released"
            assert drives(sim) == 0, "a ratioDrive left before the guardian was armed"
            assert parent.ask("armed robot1") == "armed robot1"
            assert logins(sim) == 2  # the window's and its guardian's
            assert parent.ask("press forward") == "pressed"
            eventually(lambda: driving(sim), timeout=5)
            watchdog = sim.call(lambda: sim.server.robot.watchdog_stops)
            os.kill(parent.proc.pid, signal.SIGSTOP)  # frozen while driving, seconds after connecting
            eventually(lambda: guardian_stops(sim) == 1, timeout=5)
            assert sim.call(lambda: sim.server.robot.mode_name) == "stop"
            assert sim.call(lambda: sim.server.robot.watchdog_stops) == watchdog, "the watchdog fired"
        finally:
            parent.end()


def test_a_new_selection_arms_the_one_guardian_for_that_robot_before_it_drives_and_a_kill_stops_it(
    sims: list[SimThread],
) -> None:
    first, second = sims
    with FaultProxy("127.0.0.1", second.port, later_held=HOLD) as proxy:
        parent = Parent({"robot1": first.port, "robot2": proxy.port})
        try:
            assert parent.ask("armed robot1") == "armed robot1"
            assert logins(first) == 2 and logins(second) == 1  # the guardian is at robot1 only
            assert parent.ask("select robot2") == "selected robot2"
            answer = parent.ask("press forward")
            assert answer.startswith("refused") and "arming the guardian for robot2" in answer, answer
            assert parent.ask("release forward") == "released"
            assert drives(second) == 0, "robot2 drove before the guardian was armed for it"
            assert parent.ask("armed robot2") == "armed robot2"
            eventually(lambda: logins(first) == 1, timeout=5)  # it left robot1 for robot2
            assert logins(second) == 2
            assert guardians_of(parent.proc.pid) == [parent.guardian_pid], "not ONE guardian process"
            assert parent.ask("press forward") == "pressed"
            eventually(lambda: driving(second), timeout=5)
            watchdog = second.call(lambda: second.server.robot.watchdog_stops)
            parent.proc.kill()
            eventually(lambda: guardian_stops(second) == 1, timeout=5)
            assert second.call(lambda: second.server.robot.watchdog_stops) == watchdog, "the watchdog fired"
            assert guardian_stops(first) == 0, "the robot not selected was stopped by the guardian"
            assert not driving(first)  # (it got zero ratios and a stop when robot2 was selected)
        finally:
            parent.end()
        eventually(lambda: not guardians_of(parent.proc.pid) and logins(second) == 0, timeout=10)


def test_a_clean_close_says_goodbye_and_the_guardian_stops_nothing(sims: list[SimThread]) -> None:
    first, second = sims
    parent = Parent({"robot1": first.port, "robot2": second.port})
    try:
        assert parent.ask("armed robot1") == "armed robot1"
        assert parent.ask("press forward") == "pressed"
        eventually(lambda: driving(first), timeout=5)
        assert parent.ask("close") == "closed"
        assert parent.proc.wait(10) == 0
        eventually(lambda: logins(first) == 0 and logins(second) == 0, timeout=10)
        assert sim_mode(first) == "stop"
        assert guardian_stops(first) == 0 and guardian_stops(second) == 0
    finally:
        parent.end()


def sim_mode(sim: SimThread) -> str:
    return str(sim.call(lambda: sim.server.robot.mode_name))

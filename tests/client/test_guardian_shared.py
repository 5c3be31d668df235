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

import contextlib
import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from guardians import guardian_stops, guardians_of, logins
from linkfaults import FaultProxy
from rtmu.guardian.child import WARM_MAX
from rtmu.guardian.handle import GuardianHandle
from rtmu.guardian.messages import Hello
from rtmu.sim import SimThread
from rtmu.values.target import Target
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
    # robot2, beside robot1 in the list, is kept ready by the guardian; robot3 is not, until chosen
    with running(seed=3) as beside, FaultProxy("127.0.0.1", second.port, later_held=HOLD) as proxy:
        parent = Parent({"robot1": first.port, "robot2": beside.port, "robot3": proxy.port})
        try:
            assert parent.ask("armed robot1") == "armed robot1"
            assert logins(first) == 2 and logins(second) == 1  # the guardian is not at robot3
            assert parent.ask("select robot3") == "selected robot3"
            answer = parent.ask("press forward")
            assert answer.startswith("refused") and "arming the guardian for robot3" in answer, answer
            assert parent.ask("release forward") == "released"
            assert drives(second) == 0, "robot3 drove before the guardian was armed for it"
            assert parent.ask("armed robot3") == "armed robot3"
            assert logins(second) == 2
            assert logins(first) == 2  # robot1's login is kept ready (watched no more: see below)
            assert guardians_of(parent.proc.pid) == [parent.guardian_pid], "not ONE guardian process"
            assert parent.ask("press forward") == "pressed"
            eventually(lambda: driving(second), timeout=5)
            watchdog = second.call(lambda: second.server.robot.watchdog_stops)
            parent.proc.kill()
            eventually(lambda: guardian_stops(second) == 1, timeout=5)
            assert second.call(lambda: second.server.robot.watchdog_stops) == watchdog, "the watchdog fired"
            assert guardian_stops(first) == 0, "the robot not selected was stopped by the guardian"
            assert guardian_stops(beside) == 0
            assert not driving(first)  # (it got zero ratios and a stop when robot3 was selected)
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


def test_the_robots_beside_the_selection_are_kept_ready_selecting_one_needs_no_new_login(
    sims: list[SimThread],
) -> None:
    """Arming is a login, slow on a busy server: the guardian keeps logins to the robots beside the
    selected one (and to the one selected before) ready. Selecting them opens no connection; the
    guardian still stops only the robot it watches."""
    first, second = sims
    with (
        FaultProxy("127.0.0.1", first.port) as one,
        FaultProxy("127.0.0.1", second.port, later_held=HOLD) as two,
    ):
        parent = Parent({"robot1": one.port, "robot2": two.port})
        try:
            assert parent.ask("armed robot1") == "armed robot1"
            eventually(lambda: two.connections == 2, timeout=10)  # the window's and the guardian's ready one
            assert one.connections == 2
            assert parent.ask("select robot2") == "selected robot2"
            assert parent.ask("armed robot2") == "armed robot2"
            assert parent.ask("select robot1") == "selected robot1"
            assert parent.ask("armed robot1") == "armed robot1"
            assert (one.connections, two.connections) == (2, 2), "an arming opened a new connection"
            assert logins(first) == 2 and logins(second) == 2
            assert parent.ask("press forward") == "pressed"
            eventually(lambda: driving(first), timeout=5)
            parent.proc.kill()
            eventually(lambda: guardian_stops(first) == 1, timeout=5)
            assert guardian_stops(second) == 0, "the guardian stopped a robot it only kept ready"
            assert not driving(second)  # (zero ratios and a stop when robot1 was selected again)
        finally:
            parent.end()
        eventually(lambda: logins(first) == 0 and logins(second) == 0, timeout=10)


def test_the_guardian_keeps_at_most_three_logins_ready_lets_go_when_told_and_promotes_one() -> None:
    """The ready logins are bounded (memory independent of the fleet's size): the newest
    ``WARM_MAX`` are kept, COLD lets one go, and a LOGIN for a kept robot opens no new connection."""
    assert WARM_MAX == 3
    with contextlib.ExitStack() as stack:
        robots = [stack.enter_context(running(seed=i)) for i in range(5)]
        handle = GuardianHandle.start()
        try:
            for sim in robots:
                handle.warm(Hello(Target("127.0.0.1", sim.port)))
            eventually(lambda: [logins(sim) for sim in robots] == [0, 0, 1, 1, 1], timeout=10)
            handle.cool(Hello(Target("127.0.0.1", robots[3].port)))
            eventually(lambda: [logins(sim) for sim in robots] == [0, 0, 1, 0, 1], timeout=10)
            handle.login(Hello(Target("127.0.0.1", robots[4].port), serial=7))
            eventually(lambda: handle.poll() is not None and handle.state == "ready", timeout=10)
            assert [logins(sim) for sim in robots] == [0, 0, 1, 0, 1]
        finally:
            handle.close(goodbye=True)
        eventually(lambda: sum(logins(sim) for sim in robots) == 0, timeout=10)


def sim_mode(sim: SimThread) -> str:
    return str(sim.call(lambda: sim.server.robot.mode_name))

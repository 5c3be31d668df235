"""Why won't it move? and the console on the one intent path: controller guard → runner → feed.

Against the simulator over loopback, through a robot session built as the window builds it
(recording on): the why answer names the cause the simulator was put in, a fix that needs a yes is
refused by the guard without one and works with one, the console lists, reads, follows and refuses
what it must — and every intent lands in the recording.
"""

from __future__ import annotations

import concurrent.futures
from pathlib import Path
from typing import Any

import pytest

from client.navsim import robot
from patience import cli_timeout
from recorder.mcapread import read
from recorder.simsession import recorded_session
from rtmu.base import exit_codes as codes
from rtmu.cli import main
from rtmu.client.console import NeedsConfirmation
from rtmu.recorder import topics
from rtmu.sim import SimThread
from rtmu.values.intents import ApplyFix, AskWhy, ConsoleCall, ConsoleFollow, ConsoleList, ConsoleNext

WAIT = 20.0


def command(sim: SimThread, name: str) -> None:
    assert main(["run", f"127.0.0.1:{sim.port}", name, "--timeout", cli_timeout(5)]) == codes.EXIT_OK


def answer(future: concurrent.futures.Future[Any] | None) -> Any:
    assert future is not None, "the guard refused it"
    return future.result(timeout=WAIT)


def test_why_names_the_cause_and_a_fix_needs_a_yes(tmp_path: Path) -> None:
    with recorded_session(tmp_path) as (session, ui, view, sim):
        ask = session.controller.ask
        assert answer(ask(AskWhy())).can_move
        command(sim, "SimulatorLockStopMode")
        locked = answer(ask(AskWhy(trans=50.0)))
        assert locked.exit_code == codes.EXIT_WHY_LOCKED and "will not unlock" in locked.sentence()
        command(sim, "SimulatorUnlockMode")
        command(sim, "SimulatorObstacleAhead")
        blocked = answer(ask(AskWhy(trans=50.0)))
        assert blocked.exit_code == codes.EXIT_WHY_SAFE_DRIVE
        assert blocked.primary.fix is not None and blocked.primary.fix.key == "safe_drive_off"
        assert ask(ApplyFix(key="safe_drive_off")) is None  # no yes: the guard refuses it
        ui.drain()
        assert any("not sent without the operator's confirmation" in t for t in view.texts())
        assert robot(sim).safe_drive is True
        report = answer(ask(ApplyFix(key="safe_drive_off", confirmed=True)))
        assert report.sent and report.worked and report.answer.can_move
        assert robot(sim).safe_drive is False
        gone = answer(ask(ApplyFix(key="undock", confirmed=True)))  # the robot shows nothing to undock
        assert not gone.sent and "no longer shows" in gone.message
    intents = [r["intent"] for r in read(next(tmp_path.glob("*.mcap"))).records(topics.INTENTS)]
    assert intents.count("AskWhy") == 3 and intents.count("ApplyFix") == 2  # the refused one never left


def test_the_console_lists_reads_follows_and_refuses(tmp_path: Path) -> None:
    with recorded_session(tmp_path) as (session, ui, view, sim):
        ask = session.controller.ask
        entries = answer(ask(ConsoleList()))
        assert sim.server is not None and len(entries) == len(list(sim.server.datalist))
        assert [e.name for e in answer(ask(ConsoleList(text="batteryinfo")))] == ["batteryInfo"]
        reply = answer(ask(ConsoleCall(name="getModeInfo")))
        assert reply.outcome == "replied" and reply.packets[0].typed_name == "ModeInfo"
        with pytest.raises(NeedsConfirmation):  # the feed's rule, whatever the window said
            answer(ask(ConsoleCall(name="SimulatorLockStopMode")))
        assert ask(ConsoleCall(name="ratioDrive", confirmed=True)) is None  # never the console's
        assert ask(ConsoleCall(name="stop")) is None  # a motion request: not without a yes
        assert ask(ConsoleFollow(name="gotoGoal")) is None  # and never followed
        ui.drain()
        assert any("never sent from the console" in t for t in view.texts())
        assert answer(ask(ConsoleFollow(name="update", interval_ms=100))) == "update"
        batch = answer(ask(ConsoleNext(name="update", wait=5.0)))
        assert batch and all(r.name == "update" for r in batch)
        assert answer(ask(ConsoleFollow(name="update", on=False))) is None
        assert answer(ask(ConsoleNext(name="update", wait=0.1))) == ()

"""Why won't it move? — one window test per cause the simulator can be put into, with real X input.

The robot's own state (e-stop, motors off, a stalled motor, a battery below shutdown) is put in by
the simulator's own simple commands; a held drive key must raise the hint that names it and says
what to do, ``?`` must open the why window that does the same (all but a stall: see
``asked_after``), and nothing is offered that RTMU cannot do about it. Space and the STOP button
still stop the robot (the simulator's stop log grows) in the e-stop state (with the why window
open) and the stalled state (with the hint shown). The other causes each have a test below.
"""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from rtmu.client.why_values import Cause
from rtmu.sim import SimThread
from simulators import simulator

from .harness import Gui
from .why_steps import (
    ask_why,
    command,
    hint,
    hold_up_for_the_hint,
    space_stops,
    stop_button_stops,
)

sim = simulator(map_path=None, camera=False, seed=1)


@dataclass(frozen=True)
class RobotState:
    """A state of the robot itself, how to put the simulator in it, and the words that must name it."""

    cause: Cause
    commands: tuple[tuple[str, ...], ...]
    problem: str
    """In the hint and in the why window's sentence."""
    advice: str
    """In the why window's sentence, after the problem."""
    stop_checks: bool = False
    """Press Space and click STOP in this state too."""
    asked_after: bool = True
    """The why window, opened after the drive key is let go, still names it. Not so for a stall: the
    release sends stop, and ARIA's stop mode says "Stopped" where its drive mode said "Stalled" — the
    hint, asked while the key is held, is where a stall is told."""


STATES = (
    RobotState(
        Cause.ESTOP,
        (("SimulatorEStop",),),
        "e-stop is pressed",
        "release the e-stop button on the robot",
        stop_checks=True,
    ),
    RobotState(
        Cause.MOTORS,
        (("SimulatorMotorsOff",),),
        "motors are disabled",
        "enable them on the robot",
    ),
    RobotState(
        Cause.STALLED,
        (("SimulatorStallMotors",),),
        "a motor is stalled",
        "check the wheels and bumpers",
        stop_checks=True,
        asked_after=False,
    ),
    RobotState(
        Cause.BATTERY,
        (("SimulatorSetBattery", "10.5"),),
        "shutdown level (11 V)",
        "charge the robot",
    ),
)


@pytest.mark.parametrize("state", STATES, ids=lambda s: s.cause.key)
def test_a_held_drive_against_the_robots_own_state_is_told_and_the_why_window_names_it(
    gui: Gui, sim: SimThread, state: RobotState
) -> None:
    for args in state.commands:
        command(sim, *args)
    x0 = sim.snapshot().x
    hold_up_for_the_hint(gui)
    said = hint(gui)
    assert state.problem in said and state.advice in said and "(?)" in said, said
    assert abs(sim.snapshot().x - x0) < 10.0
    if not state.asked_after:
        if state.stop_checks:
            space_stops(gui, sim, f"with the {state.cause.key} hint shown")
            stop_button_stops(gui, sim, f"with the {state.cause.key} hint shown")
        return
    why = ask_why(gui)
    sentence = why.sentence.get_text()
    assert why.answer is not None and why.answer.primary is not None, sentence
    assert why.answer.primary.cause is state.cause, sentence
    assert state.problem in sentence and state.advice in sentence, sentence
    assert not why.fix_button.get_visible()  # nothing RTMU can do here: the words say what to do
    gui.render(why, gui.shots / f"{gui.name}-why.png")
    if state.stop_checks:
        space_stops(gui, sim, f"with the {state.cause.key} why window holding the keys")
        stop_button_stops(gui, sim, f"with the {state.cause.key} why window open")

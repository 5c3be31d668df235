"""Why won't it move? — one window test per cause the simulator can be put into, with real X input.

The robot's own state (e-stop, motors off, a stalled motor, a battery below shutdown) is put in by
the simulator's own simple commands; a held drive key must raise the hint that names it and says
what to do, ``?`` must open the why window that does the same (a stall as a note of what the hint
found: see ``shown_after``), and nothing is offered that RTMU cannot do about it. Space and the
STOP button still stop the robot (the simulator's stop log grows) in the e-stop and the stalled
states, with the why window open.

Below, each other cause the simulator can be put into: navigating, docked and an LD robot's motors
off (the fix offered, asked first, and nothing at the simulator before the yes); a lost robot
(noted for navigation: driving by hand needs no localization); a login without Stop (warned at
login and marked ⚠); a drive key held through a stop; a window that froze while driving (the
lease lapsed); a drive watchdog shorter than RTMU's resend; a link that is down, and one that
carries nothing (answered without asking); a gamepad stick pushed so little that ARIA ignores it.
"""

from __future__ import annotations

import time
from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path

import pytest

from linkfaults import FaultProxy
from patience import cli_timeout
from rtmu.base import exit_codes as codes
from rtmu.cli import main
from rtmu.client.why_feed import NOT_ASKED_OVER_A_BAD_LINK
from rtmu.client.why_values import Cause
from rtmu.control.gamepad import AXIS_TRANS, DEADMAN, stick_ratios
from rtmu.model.observables import Phase
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.ld_safety import safety_state
from rtmu.values.state import LinkLevel
from simulators import running, simulator, users_file

from .harness import OFFICE_MAP, Gui, idle, pump
from .process import PATIENCE
from .why_steps import (
    ask_why,
    command,
    free_again,
    hint,
    hold_up_for_the_hint,
    offer_the_fix,
    say_yes,
    space_stops,
    stop_button_stops,
    stops,
)

sim = simulator(map_path=None, camera=False, seed=1)
PAD = object()
GENTLE = 0.28
"""A stick deflection just past the pad's own dead zone: 10 % translation, inside ARIA's."""
assert stick_ratios(0.0, -GENTLE) == (10.0, 0.0)
FROZEN = 1.0
"""Seconds the window's thread is stopped: over three times the drive lease's 0.3 s."""


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
    shown_after: bool = True
    """The server still shows it once the drive key is let go, so the why window names it as the cause.
    Not so for a stall: the release sends stop, and ARIA's stop mode says "Stopped" where its drive mode
    said "Stalled" — the why window then recalls what the hint found, as a note."""


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
        shown_after=False,
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
    why = ask_why(gui)
    sentence = why.sentence.get_text()
    assert why.answer is not None
    if state.shown_after:
        assert why.answer.primary is not None and why.answer.primary.cause is state.cause, sentence
        assert state.problem in sentence and state.advice in sentence, sentence
    else:
        details = why.details.get_text()
        assert sentence.startswith("Nothing RTMU can read keeps the robot from moving"), sentence
        assert "while the drive was held" in details and state.problem in details, details
    assert not why.fix_button.get_visible()  # nothing RTMU can do here: the words say what to do
    gui.render(why, gui.shots / f"{gui.name}-why.png")
    if state.stop_checks:
        space_stops(gui, sim, f"with the {state.cause.key} why window holding the keys")
        stop_button_stops(gui, sim, f"with the {state.cause.key} why window open")


# -- causes with a fix: offered, asked first, sent only after the yes -----------------------------------
office = simulator(map_path=OFFICE_MAP, camera=False, seed=1)


def test_navigating_is_named_and_its_stop_is_sent_only_after_a_yes(
    screenshots: Path, office: SimThread
) -> None:
    gui = Gui.start(screenshots, "test_why_navigating", "127.0.0.1", office.port)
    try:
        addr = f"127.0.0.1:{office.port}"
        assert main(["goto", addr, "Corridor End", "--no-wait", "--timeout", cli_timeout(5)]) == codes.EXIT_OK
        pump(lambda: office.snapshot().status.startswith("Going to"), 10, "the robot to navigate")
        why = ask_why(gui)
        sentence = why.sentence.get_text()
        assert "driving the robot itself (Corridor End)" in sentence and "press STOP first" in sentence
        assert office.snapshot().status.startswith("Going to")  # looking never stops it
        before = stops(office)
        offer_the_fix(gui, why, "Stop the navigation…")
        assert "RTMU will send stop" in why.confirm.question.get_text()
        gui.render(why, gui.shots / f"{gui.name}-confirm.png")
        idle(0.5)
        assert stops(office) == before and office.snapshot().status.startswith("Going to")
        say_yes(gui, why)
        pump(lambda: stops(office) > before, 10, "the stop the yes sends")
        free_again(why)
        assert office.snapshot().mode_name == "stop" and "done" in why.status.get_text()
    finally:
        gui.close()


def test_docked_is_named_and_undock_is_sent_only_after_a_yes(screenshots: Path, office: SimThread) -> None:
    gui = Gui.start(screenshots, "test_why_docked", "127.0.0.1", office.port)
    try:
        addr = f"127.0.0.1:{office.port}"
        assert main(["dock", addr, "--timeout", cli_timeout(5), "--limit", "60"]) == codes.EXIT_OK
        why = ask_why(gui)
        sentence = why.sentence.get_text()
        assert sentence.startswith("The robot is docked (charging)") and "undock it first" in sentence
        x0 = office.snapshot().x
        offer_the_fix(gui, why, "Undock…")
        assert "RTMU will send undock" in why.confirm.question.get_text()
        idle(0.5)
        assert office.snapshot().status == "Docked" and office.snapshot().x == x0  # nothing before the yes
        say_yes(gui, why)
        pump(lambda: office.snapshot().status != "Docked", 10, "the robot to undock")
        free_again(why)
        assert office.snapshot().x != x0 and "done" in why.status.get_text()  # it backed out
        gui.render(why, gui.shots / f"{gui.name}-undocked.png")
    finally:
        gui.close()


def test_a_lost_robot_is_noted_for_navigation_while_driving_by_hand_stays_free(
    screenshots: Path, office: SimThread
) -> None:
    gui = Gui.start(screenshots, "test_why_lost", "127.0.0.1", office.port)
    try:
        command(office, "SimulatorLoseLocalization")
        why = ask_why(gui)
        assert why.sentence.get_text().startswith("Nothing RTMU can read keeps the robot from moving")
        details = why.details.get_text()
        assert "but navigation is: the robot is lost" in details and "tell it where it is" in details, details
        gui.render(why, gui.shots / f"{gui.name}-why.png")
    finally:
        gui.close()


def test_an_ld_robots_motors_are_enabled_only_after_a_yes(screenshots: Path) -> None:
    with SimThread(SimConfig(port=0, profile="aram", map_path=None, camera=False, test_hooks=True)) as aram:
        assert aram.server is not None
        state = safety_state(aram.server)
        gui = Gui.start(screenshots, "test_why_ld_motors", "127.0.0.1", aram.port)
        try:
            command(aram, "SimulatorMotorsOff")
            why = ask_why(gui)
            assert "motors are disabled" in why.sentence.get_text(), why.sentence.get_text()
            offer_the_fix(gui, why, "Enable the motors…")
            question = why.confirm.question.get_text()
            assert "enableMotors" in question and "powers the robot's wheels" in question
            gui.render(why, gui.shots / f"{gui.name}-confirm.png")
            idle(0.5)
            assert state.enables == 0  # nothing enabled before the yes
            say_yes(gui, why)
            pump(lambda: state.enables == 1, 10, "enableMotors")
            free_again(why)
        finally:
            gui.close()


# -- who is logged in -------------------------------------------------------------------------------------
def test_a_user_without_stop_is_warned_loudly_at_login_and_by_the_why_window(
    screenshots: Path, tmp_path: Path
) -> None:
    users = users_file(tmp_path, "carol pw RobotInfo SensorInfo Movement")
    with running(map_path=None, camera=False, users_path=users, seed=1) as carol_sim:
        gui = Gui.start(
            screenshots, "test_why_no_stop", "127.0.0.1", carol_sim.port, connect=False, user="carol"
        )
        try:
            gui.window.controller.connect(password="pw")
            gui.wait_connected()
            said = lambda: [(level, text) for _t, level, text in gui.window.banners.history]  # noqa: E731
            pump(lambda: any("may not send stop" in text for _l, text in said()), 10, "the login's warning")
            level, text = next((lv, t) for lv, t in said() if "may not send stop" in t)
            assert level in ("warning", "error") and "SAFETY: user 'carol'" in text, (level, text)
            gui.shot("warned")
            why = ask_why(gui)
            sentence = why.sentence.get_text()
            assert sentence.startswith("⚠ SAFETY: user 'carol' may not send stop"), sentence
            assert "use one whose groups include Stop" in sentence and why.sentence.has_css_class("error")
            assert why.answer is not None and why.answer.exit_code == codes.EXIT_WHY_NO_STOP
            gui.render(why, gui.shots / f"{gui.name}-why.png")
        finally:
            gui.close()


# -- our own side of the drive ------------------------------------------------------------------------------
def test_a_drive_key_held_through_a_stop_is_told_to_be_let_go(gui: Gui, sim: SimThread) -> None:
    gui.focus()
    gui.keydown("Up")
    try:
        pump(lambda: sim.snapshot().vel > 50, 10, "the robot to drive")
        space_stops(gui, sim, "with Up still held")
        pump(lambda: bool(hint(gui)), 15, "the hint of a held key the stop made void")
        said = hint(gui)
        assert "held through a stop is ignored" in said and "let go of the key" in said, said
        x = sim.snapshot().x
        idle(0.5)
        assert abs(sim.snapshot().x - x) < 10.0  # the held key still drives nothing
        gui.shot("hint")
    finally:
        gui.keyup("Up")


def test_a_server_watchdog_shorter_than_our_resend_is_named(screenshots: Path) -> None:
    with running(map_path=None, camera=False, drive_timeout=0.05, seed=1) as quick:
        gui = Gui.start(screenshots, "test_why_watchdog", "127.0.0.1", quick.port)
        try:
            why = ask_why(gui)
            sentence = why.sentence.get_text()
            assert why.answer is not None and why.answer.exit_code == codes.EXIT_WHY_WATCHDOG, sentence
            assert "drive watchdog is 0.05 s" in sentence and "raise the Teleop Timeout" in sentence
            assert (
                not why.fix_button.get_visible()
            )  # the server's configuration: RTMU does not change it here
            gui.render(why, gui.shots / f"{gui.name}-why.png")
        finally:
            gui.close()


def test_a_link_that_is_down_is_named(screenshots: Path) -> None:
    with ExitStack() as server_side:
        server = server_side.enter_context(running(map_path=None, camera=False, seed=1))
        gui = Gui.start(screenshots, "test_why_link_down", "127.0.0.1", server.port)
        try:
            server_side.close()  # the server goes away under the window
            pump(lambda: gui.phase is not Phase.CONNECTED, 15, "the window to see the link go")
            why = ask_why(gui)
            sentence = why.sentence.get_text()
            assert sentence.startswith("Our link to the robot is down (not connected)"), sentence
            assert "check the network" in sentence and not why.fix_button.get_visible()
            assert why.answer is not None and why.answer.exit_code == codes.EXIT_WHY_LINK
            gui.render(why, gui.shots / f"{gui.name}-why.png")
        finally:
            gui.close()


def test_a_gentle_stick_inside_arias_dead_zone_is_told(gui: Gui, sim: SimThread) -> None:
    """A stick pushed a little drives 10 %, which ARIA ignores: the hint must name the dead zone (the
    pad's events go to the window's own Gamepad as libmanette would give them, as test_fleet_gamepad)."""
    pad = gui.window.handheld.pad
    assert pad.connected(PAD, "Test pad")
    gui.focus()
    x0 = sim.snapshot().x
    pad.button(PAD, DEADMAN, True)
    try:
        end = time.monotonic() + 15 * PATIENCE
        while not hint(gui):  # the stick's noise keeps the pad talking, as a real one does
            assert time.monotonic() < end, "no hint for a stick inside the dead zone"
            pad.axis(PAD, AXIS_TRANS, -GENTLE)
            idle(0.05)
        said = hint(gui)
        assert "inside ARIA's dead zone" in said and "ask for more than 10 % translation" in said, said
        assert sim.call(lambda: sim.server.world.ratio_drives_received) > 0  # type: ignore[union-attr]
        assert abs(sim.snapshot().x - x0) < 1.0  # sent, and ARIA's dead zone swallowed it
        gui.shot("hint")
    finally:
        pad.button(PAD, DEADMAN, False)
        pad.disconnected(PAD)


def test_a_window_that_froze_while_driving_is_named_as_the_stop(gui: Gui, sim: SimThread) -> None:
    """The window's own thread (this test's) stops for a second while Up is held: the lease lapses, RTMU
    stops the robot, and the why window says it was our side, not the robot."""
    gui.focus()
    gui.keydown("Up")
    try:
        pump(lambda: sim.snapshot().vel > 50, 10, "the robot to drive")
        time.sleep(FROZEN)  # the GTK thread is frozen: nothing renews the drive
        pump(lambda: sim.snapshot().vel == 0, 10, "the lapsed drive to stop the robot")
    finally:
        gui.keyup("Up")
    why = ask_why(gui)
    sentence = why.sentence.get_text()
    assert why.answer is not None and why.answer.exit_code == codes.EXIT_WHY_LEASE, sentence
    assert "did not renew the drive in time" in sentence and "press the drive key again" in sentence
    gui.render(why, gui.shots / f"{gui.name}-why.png")


def test_a_stale_link_is_named_at_once(faulty_link: tuple[Gui, SimThread, FaultProxy]) -> None:
    """The server's bytes are held back (a dead Wi-Fi): the why window answers from our side without
    asking the robot — over that link each reply would only be waited out (it hung "Asking the
    robot…" for a minute before)."""
    gui, _sim, proxy = faulty_link
    proxy.mute()
    pump(lambda: gui.model.health.value.level is not LinkLevel.OK, 10, "the window to see the link go bad")
    why = ask_why(gui)
    sentence = why.sentence.get_text()
    assert sentence.startswith("Our link to the robot is "), sentence
    assert "check the network" in sentence and not why.fix_button.get_visible()
    assert why.answer is not None and why.answer.exit_code == codes.EXIT_WHY_LINK
    assert NOT_ASKED_OVER_A_BAD_LINK in why.answer.notes  # nothing was asked over the dead link
    gui.render(why, gui.shots / "test_why_stale_link-why.png")
    proxy.restore()

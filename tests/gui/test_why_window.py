"""Why won't it move? — in the real window, against the simulator put into each cause by its own commands.

Real window, real simulator, real X keys and clicks: a drive key held against a locked mode raises
the hint within a few seconds and names the lock; ``?`` and the menu (by keyboard) open the why
window; a fix (safe drive off) is offered behind a confirmation and nothing is sent before its yes;
a user without Movement is told so by the hint; a lock that gives way is unlocked by its fix, asked
first in the window; an LD robot's fault is told at once and acknowledged only after the yes. Space
and the STOP button stop the robot (the simulator's stop log grows) with the why window and its
confirmation open.
"""

from __future__ import annotations

from pathlib import Path

from rtmu.sim import SimConfig, SimThread
from rtmu.sim.ld_safety import safety_state
from simulators import simulator

from .harness import Gui, idle, pump
from .stop_paths import MenuPicker
from .why_steps import (
    WHY_ROW,
    click_in,
    command,
    hint,
    hold_up_for_the_hint,
    space_stops,
    stop_button_stops,
    why_window,
    xid,
)

sim = simulator(map_path=None, camera=False, seed=1)


def test_a_locked_mode_raises_the_hint_and_the_why_window_names_it(gui: Gui, sim: SimThread) -> None:
    command(sim, "SimulatorLockStopMode")
    x0 = sim.snapshot().x
    hold_up_for_the_hint(gui)
    assert "will not unlock" in hint(gui), hint(gui)
    assert gui.window.why_hint.asked == 1  # once per held drive
    assert abs(sim.snapshot().x - x0) < 1.0
    space_stops(gui, sim, "with the hint shown")
    gui.focus()
    gui.key("question")
    why = why_window(gui)
    assert "will not unlock" in why.sentence.get_text() and not why.fix_button.get_visible()
    gui.render(why, gui.shots / f"{gui.name}-why-locked.png")
    space_stops(gui, sim, "with the why window holding the keys")
    stop_button_stops(gui, sim, "with the why window open")
    command(sim, "SimulatorUnlockMode")
    gui.xdotool("windowfocus", "--sync", str(xid(why)))
    click_in(gui, why.again_button)
    pump(lambda: not why.asking and why.answer is not None and why.answer.can_move, 15, "the new answer")
    assert why.sentence.get_text().startswith("Nothing RTMU can read keeps the robot from moving")
    gui.render(why, gui.shots / f"{gui.name}-why-free.png")


def test_an_obstacle_inside_safe_drive_its_fix_asks_first_and_works(gui: Gui, sim: SimThread) -> None:
    command(sim, "SimulatorObstacleAhead")
    gui.focus()
    MenuPicker(gui).by_keyboard(WHY_ROW)
    why = why_window(gui)
    assert "safe drive" in why.sentence.get_text().lower(), why.sentence.get_text()
    assert why.fix_button.get_visible() and why.fix_button.get_label() == "Switch safe drive off…"
    gui.xdotool("windowfocus", "--sync", str(xid(why)))
    pump(why.is_active, 5, "the why window to have the keyboard")
    why.fix_button.grab_focus()
    gui.key("Return")  # the keyboard reaches the fix: it only asks
    pump(lambda: why.confirm.asking and why.confirm.cancel_button.has_focus(), 5, "the confirmation")
    assert "lets the robot drive into things" in why.confirm.question.get_text()
    gui.render(why, gui.shots / f"{gui.name}-confirm.png")
    idle(0.5)
    assert sim.snapshot().safe_drive is True  # nothing sent before the yes
    space_stops(gui, sim, "with the confirmation open")
    stop_button_stops(gui, sim, "with the confirmation open")
    gui.xdotool("windowfocus", "--sync", str(xid(why)))
    if not why.confirm.asking:
        click_in(gui, why.fix_button)
    pump(lambda: why.confirm.asking, 5, "the confirmation again")
    assert sim.snapshot().safe_drive is True
    click_in(gui, why.confirm.yes_button)
    pump(lambda: sim.snapshot().safe_drive is False, 10, "safe drive to go off")
    pump(lambda: not why.asking and why.answer is not None and why.answer.can_move, 15, "the new answer")
    assert "done" in why.status.get_text()
    gui.render(why, gui.shots / f"{gui.name}-fixed.png")


def test_a_user_without_movement_is_told_by_the_hint(screenshots: Path, tmp_path: Path) -> None:
    users = tmp_path / "users.txt"
    users.write_text("UserInfoVersion1\nuser bob pw RobotInfo SensorInfo Stop\n")
    with SimThread(SimConfig(port=0, map_path=None, camera=False, users_path=users, seed=1)) as sim:
        gui = Gui.start(screenshots, "test_no_movement", "127.0.0.1", sim.port, connect=False, user="bob")
        try:
            gui.window.controller.connect(password="pw")
            gui.wait_connected()
            hold_up_for_the_hint(gui)
            assert "'bob' may not drive" in hint(gui), hint(gui)
            stop_button_stops(gui, sim, "for a user who may stop but not drive")
        finally:
            gui.close()


def test_a_lock_that_gives_way_is_unlocked_by_its_fix_after_a_yes(gui: Gui, sim: SimThread) -> None:
    command(sim, "SimulatorLockStopModeUnlockable")
    gui.focus()
    gui.key("question")
    why = why_window(gui)
    assert "will unlock" in why.sentence.get_text(), why.sentence.get_text()
    assert why.fix_button.get_label() == "Ask the mode to unlock…"
    gui.xdotool("windowfocus", "--sync", str(xid(why)))
    click_in(gui, why.fix_button)
    pump(lambda: why.confirm.asking, 5, "the confirmation")  # a fix the CLI sends without a yes: asked here
    idle(0.3)
    assert _locked(sim)
    click_in(gui, why.confirm.yes_button)
    pump(lambda: not why.asking and why.answer is not None and why.answer.can_move, 15, "the new answer")
    assert not _locked(sim) and "done" in why.status.get_text()
    gui.render(why, gui.shots / f"{gui.name}-unlocked.png")


def test_an_ld_fault_is_told_at_once_and_acknowledged_only_after_a_yes(screenshots: Path) -> None:
    with SimThread(SimConfig(port=0, profile="aram", map_path=None, camera=False, test_hooks=True)) as sim:
        assert sim.server is not None
        state = safety_state(sim.server)
        gui = Gui.start(screenshots, "test_ld_fault", "127.0.0.1", sim.port)
        try:
            command(sim, "SimulatorFault")
            said = lambda: " ".join(text for _t, _l, text in gui.window.banners.history)  # noqa: E731
            pump(lambda: "The robot reports 1 fault:" in said(), 10, "the fault notice")
            gui.shot("fault-notice")
            gui.focus()
            gui.key("question")
            why = why_window(gui)
            assert (
                "Drive fault 1" in why.sentence.get_text()
                and "raw, layout not public" in why.details.get_text()
            )
            assert why.fix_button.get_label() == "Acknowledge the faults…"
            gui.xdotool("windowfocus", "--sync", str(xid(why)))
            click_in(gui, why.fix_button)
            pump(lambda: why.confirm.asking, 5, "the confirmation")
            assert "acknowledgeFault" in why.confirm.question.get_text()
            space_stops(gui, sim, "with the fault's confirmation open")
            assert state.acknowledged == []  # nothing acknowledged without the yes
            gui.xdotool("windowfocus", "--sync", str(xid(why)))
            if not why.confirm.asking:
                click_in(gui, why.fix_button)
            pump(lambda: why.confirm.asking, 5, "the confirmation again")
            click_in(gui, why.confirm.yes_button)
            pump(lambda: state.acknowledged != [], 10, "the acknowledgement")
            assert state.acknowledged == ["Drive fault 1: simulated motor controller fault"]
            pump(lambda: not why.asking and why.answer is not None and why.answer.can_move, 15, "the answer")
            gui.render(why, gui.shots / f"{gui.name}-acknowledged.png")
        finally:
            gui.close()


def _locked(sim: SimThread) -> bool:
    return bool(sim.call(lambda: sim.server.world.mode.locked))  # type: ignore[union-attr]

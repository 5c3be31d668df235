"""The gamepad drives the selected robot only, and never carries over to the next one.

Two simulated robots in one window (real loopback servers, the real window, rows clicked with
xdotool). The pad's events are given to the window's own ``Gamepad`` as the libmanette adapter
would (no pad on a test machine); what is checked is what each simulator did.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from rtmu.control.gamepad import AXIS_TRANS, DEADMAN, DeadMan, Gamepad
from rtmu.settings.store import DirectRobot
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.multi import SimFleetThreads, fleet_configs
from rtmu.ui.options import GuiOptions

from .harness import OFFICE_MAP, Gui, idle, pump, scratch_dir

PAD = object()


@pytest.fixture
def sims() -> Iterator[list[SimThread]]:
    with SimFleetThreads(fleet_configs(SimConfig(port=0, map_path=OFFICE_MAP, camera=False), 2)) as fleet:
        yield fleet.sims


def mode(sim: SimThread) -> str:
    return str(sim.call(lambda: sim.server.robot.mode_name))


def drives(sim: SimThread) -> int:
    return int(sim.call(lambda: sim.server.robot.ratio_drives_received))


def press_deadman(pad: Gamepad) -> None:
    pad.button(PAD, DEADMAN, False)
    pad.button(PAD, DEADMAN, True)


def drive_until(gui: Gui, pad: Gamepad, moving: SimThread, within: float = 10.0) -> None:
    """Hold the dead-man and push the stick (a real stick's noise keeps the pad talking) until it drives."""
    end = time.monotonic() + within
    while mode(moving) != "ratioDrive" or moving.snapshot().vel <= 0:
        focused = gui.window.is_active()
        assert time.monotonic() < end, f"the pad did not drive (pad {pad.state}, focus {focused})"
        if pad.state.deadman is DeadMan.LATCHED:  # a loaded machine froze the UI and the lease lapsed:
            press_deadman(pad)  # as an operator would, press again
        pad.axis(PAD, AXIS_TRANS, -1.0)
        idle(0.05)


def test_the_pad_drives_the_selected_robot_and_a_switch_needs_a_fresh_deadman(
    screenshots: Path, sims: list[SimThread]
) -> None:
    robots = tuple(DirectRobot(f"robot{i + 1}", "127.0.0.1", sim.port) for i, sim in enumerate(sims))
    settings = scratch_dir("settings-") / "settings.toml"
    options = GuiOptions(fleet=robots, settings_path=settings, persist=False)
    gui = Gui.open(options, screenshots, "fleet-gamepad")
    fleet = gui.app.fleet
    pad = gui.window.handheld.pad
    try:
        pump(lambda: len(fleet) == 2, 10, "two robot sessions")
        pump(lambda: all(s.state.robot.value.numbers_at is not None for s in fleet), 15, "robot status")
        gui.focus()
        pump(lambda: gui.window.is_active(), 5, "the window to have the focus")
        assert pad.connected(PAD, "Test pad")
        pad.axis(PAD, AXIS_TRANS, -1.0)
        pad.button(PAD, DEADMAN, True)
        drive_until(gui, pad, sims[0])
        assert drives(sims[1]) == 0, "the robot not selected was sent a drive"

        binding = gui.app.fleet_binding
        assert binding is not None
        second = fleet.named("robot2")
        assert second is not None
        row = binding.robot_list.row_of(second)
        assert row is not None
        gui.click(row)  # the dead-man is still held
        pump(lambda: fleet.selected.value is second, 5, "robot2 to be selected")
        pump(lambda: mode(sims[0]) == "stop" and sims[0].snapshot().vel == 0, 5, "robot1 to stop")
        assert pad.state.deadman is DeadMan.LATCHED, pad.state
        start2 = sims[1].snapshot()
        ratio_drives1 = drives(sims[0])
        end = time.monotonic() + 1.0
        while time.monotonic() < end:  # the stick still deflected, dead-man still down
            pad.axis(PAD, AXIS_TRANS, -1.0)
            idle(0.05)
        gui.shot("switched-deadman-held")
        now2 = sims[1].snapshot()
        assert drives(sims[1]) == 0 and (now2.x, now2.y, now2.vel) == (start2.x, start2.y, 0), (
            "robot2 moved without a fresh dead-man press"
        )
        assert drives(sims[0]) == ratio_drives1 and mode(sims[0]) == "stop", "the pad still drove robot1"

        press_deadman(pad)  # a fresh press drives the robot now selected
        drive_until(gui, pad, sims[1])
        gui.shot("robot2-on-the-pad")
        pad.button(PAD, DEADMAN, False)
        pump(lambda: mode(sims[1]) == "stop" or sims[1].snapshot().vel == 0, 5, "robot2 to stop on release")
        assert drives(sims[0]) == ratio_drives1 and sims[0].snapshot().vel == 0
    finally:
        pad.button(PAD, DEADMAN, False)
        pad.disconnected(PAD)
        gui.close()

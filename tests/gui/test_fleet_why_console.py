"""In a fleet, the why window and the console follow the selected robot (real keys, two simulators).

Robot 1 (a Pioneer-like simulator) has its stop mode locked; robot 2 is an LD robot (the aram
profile) and free. With both pages open, Alt+2 makes the why window ask robot 2 and the console
read robot 2's data list; Alt+1 turns both back. Nothing either page shows belongs to the robot
selected before.
"""

from __future__ import annotations

from pathlib import Path

from rtmu.base import exit_codes as codes
from rtmu.cli import main
from rtmu.settings.store import DirectRobot
from rtmu.sim import SimConfig, SimThread
from rtmu.ui.console_page import ConsolePage
from rtmu.ui.options import GuiOptions
from rtmu.ui.why_window import WhyWindow

from .harness import Gui, pump, scratch_dir
from .stop_paths import owned_windows


def names(sim: SimThread) -> list[str]:
    return [e.name for e in sim.server.datalist]  # type: ignore[union-attr]


def test_the_why_window_and_the_console_follow_the_selected_robot(screenshots: Path) -> None:
    with (
        SimThread(SimConfig(port=0, map_path=None, camera=False, seed=1)) as pioneer,
        SimThread(SimConfig(port=0, map_path=None, camera=False, profile="aram")) as ld,
    ):
        assert main(["run", f"127.0.0.1:{pioneer.port}", "SimulatorLockStopMode"]) == codes.EXIT_OK
        robots = (DirectRobot("pioneer", "127.0.0.1", pioneer.port), DirectRobot("ld", "127.0.0.1", ld.port))
        options = GuiOptions(fleet=robots, settings_path=scratch_dir("settings-") / "s.toml", persist=False)
        gui = Gui.open(options, screenshots, "fleet-why-console")
        try:
            fleet, window = gui.app.fleet, gui.window
            pump(lambda: len(fleet) == 2, 10, "two robot sessions")
            pump(lambda: all(s.state.robot.value.numbers_at is not None for s in fleet), 15, "both robots")
            gui.focus()
            gui.key("question")
            pump(lambda: any(isinstance(w, WhyWindow) for w in owned_windows(window)), 5, "the why window")
            why = next(w for w in owned_windows(window) if isinstance(w, WhyWindow))
            pump(lambda: why.answer is not None and not why.asking, 15, "robot 1's answer")
            assert why.answer is not None and why.answer.exit_code == codes.EXIT_WHY_LOCKED
            window.activate_action("win.console", None)
            pump(lambda: any(isinstance(w, ConsolePage) for w in owned_windows(window)), 5, "the console")
            console = next(w for w in owned_windows(window) if isinstance(w, ConsolePage))
            pump(lambda: [e.name for e in console.entries] == names(pioneer), 15, "robot 1's list")
            for number, sim, locked in ((2, ld, False), (1, pioneer, True)):
                gui.focus()
                gui.key(f"alt+{number}")
                pump(lambda n=number: window.robot.session is fleet.sessions.value[n - 1], 5, f"Alt+{number}")
                pump(
                    lambda s=sim: [e.name for e in console.entries] == names(s), 15, f"robot {number}'s list"
                )
                expected = codes.EXIT_WHY_LOCKED if locked else codes.EXIT_OK
                pump(
                    lambda e=expected: (
                        why.answer is not None and not why.asking and why.answer.exit_code == e
                    ),
                    15,
                    f"robot {number}'s answer",
                )
                gui.render(why, gui.shots / f"{gui.name}-why-robot{number}.png")
            assert "getConfigValues" in names(ld) and "getConfigValues" not in names(pioneer)
        finally:
            gui.close()

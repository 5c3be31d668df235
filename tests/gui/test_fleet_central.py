"""A profile that names ARIA's central server: the window follows the robots it lists.

A real central server with real simulated robots switched to it (``CentralThread``: the same code as
``rtmu sim --central --robots 3``, on loopback), a settings file whose profile says
``central = "127.0.0.1:PORT"``, the real window driven with xdotool. What is checked is what the
simulators did and what the window shows:

* the robots appear in the list as the central server lists them; one that switches in later
  appears live, one that leaves disappears and its session is closed with its robot stopped;
* a held key drives the selected robot through its forwarded port while the others stay still;
* the central server killed: every drive stops (at the simulated robots) and the window says so once;
  restarted: its robots come back, and a key held all along drives none of them until pressed again.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import pytest

from rtmu.fleet.sessions import RobotSession
from rtmu.settings.store import Profile, Settings, save_settings
from rtmu.sim import SimConfig
from rtmu.sim.central_thread import CentralThread
from rtmu.sim.server import SimServer
from rtmu.ui.options import GuiOptions
from rtmu.ui.robot_list import row_text

from .harness import OFFICE_MAP, Gui, idle, pump, scratch_dir


@pytest.fixture
def central() -> Iterator[CentralThread]:
    with CentralThread(robots=3, template=SimConfig(port=0, camera=False, map_path=OFFICE_MAP)) as fleet:
        yield fleet


def open_central(
    screenshots: Path, name: str, central: CentralThread, robots: int = 3, *, saved: bool = True
) -> Gui:
    """The window on a saved profile that names ``central`` (as a user's settings file would), or
    on ``rtmu --central HOST:PORT`` (``saved=False``)."""
    settings_path = scratch_dir("settings-") / "settings.toml"
    where = f"127.0.0.1:{central.port}"
    if saved:
        save_settings(Settings({"hq": Profile("hq", central=where)}, "hq"), settings_path)
        options = GuiOptions(profile="hq", settings_path=settings_path, persist=False)
    else:
        options = GuiOptions(central=where, settings_path=settings_path, persist=False)
    gui = Gui.open(options, screenshots, name, connect=False)
    fleet = gui.app.fleet
    pump(lambda: len(fleet) == robots, 15, f"{robots} robot sessions from the central server")
    pump(lambda: all(s.state.connection.value.connected for s in fleet), 20, "every robot to connect")
    pump(lambda: all(s.state.robot.value.numbers_at is not None for s in fleet), 15, "every robot's status")
    gui.wait_armed()
    return gui


def names(gui: Gui) -> list[str]:
    return [row_text(s).name for s in gui.app.fleet]


def session(gui: Gui, name: str) -> RobotSession:
    found = gui.app.fleet.named(name)
    assert found is not None, f"{name} is not in the fleet: {names(gui)}"
    return found


def at(central: CentralThread, name: str) -> tuple[float, float, float, float, int]:
    """The simulated robot's pose, speed and ratio-drive count, read on its loop."""
    sim: SimServer = central.sims[name]

    def read() -> tuple[float, float, float, float, int]:
        snap = sim.world.snapshot()
        return (snap.x, snap.y, snap.th, snap.vel, sim.robot.ratio_drives_received)

    return central.call(read)


def click_row(gui: Gui, name: str) -> None:
    binding = gui.app.fleet_binding
    assert binding is not None
    row = binding.robot_list.row_of(session(gui, name))
    assert row is not None
    gui.click(row)
    pump(lambda: gui.app.fleet.selected.value is session(gui, name), 5, f"{name} to be selected")
    gui.wait_armed(session(gui, name))  # it drives on a key pressed once its guardian can stop it


def test_the_central_servers_robots_are_listed_live_and_one_drives_alone(
    screenshots: Path, central: CentralThread
) -> None:
    gui = open_central(screenshots, "central-live-list", central)
    try:
        assert sorted(names(gui)) == sorted(central.robots()) == ["robot1", "robot2", "robot3"]
        binding = gui.app.fleet_binding
        assert binding is not None
        # The list follows the roster at its own pace (at most every 150 ms): waited for, not assumed.
        pump(lambda: binding.robot_list.get_mapped(), 5, "the robot list on screen")
        gui.shot("three-listed")

        central.add_robot("late")  # switches in while the window is open
        pump(lambda: "late" in names(gui), 15, "the late robot in the list")
        late = session(gui, "late")
        pump(lambda: late.state.connection.value.connected, 15, "the late robot to connect")
        pump(lambda: binding.robot_list.row_of(late) is not None, 5, "the late robot's row")
        gui.shot("late-listed")

        leaving = session(gui, "robot3")
        central.stop_robot("robot3")
        pump(lambda: "robot3" not in names(gui), 15, "robot3 to leave the list")
        assert leaving.closed  # the list follows the roster at its own pace (~150 ms)
        pump(lambda: binding.robot_list.row_of(leaving) is None, 5, "robot3's row to go")
        assert any("robot3 left the fleet" in text for _t, _l, text in gui.window.banners.history)

        click_row(gui, "robot2")
        before = {n: at(central, n) for n in ("robot1", "robot2", "late")}
        gui.focus()
        gui.keydown("Up")
        pump(lambda: at(central, "robot2")[3] > 0, 10, "robot2 to move through its forwarded port")
        idle(0.8)
        gui.shot("robot2-driving")
        gui.keyup("Up")
        pump(lambda: at(central, "robot2")[3] == 0, 5, "robot2 to stop after the release")
        assert math.dist(at(central, "robot2")[:2], before["robot2"][:2]) > 50, "robot2 did not drive"
        for other in ("robot1", "late"):
            assert at(central, other)[:3] == before[other][:3], f"{other} moved while robot2 was driven"
            # (robot1 was sent zero ratios and a stop when robot2 was selected, before ``before``)
            assert at(central, other)[4] == before[other][4], f"{other} was sent a drive command"
        assert at(central, "late")[4] == 0
    finally:
        gui.keyup("Up")
        gui.close()


def test_the_central_server_killed_stops_every_drive_and_is_said_once(
    screenshots: Path, central: CentralThread
) -> None:
    gui = open_central(screenshots, "central-killed", central, saved=False)  # as rtmu --central HOST:PORT
    try:
        gui.focus()
        gui.keydown("Up")
        first = gui.app.fleet.selected.value
        assert first is not None
        pump(lambda: at(central, first.name)[3] > 0, 10, f"{first.name} to drive")
        central.kill_central()  # every operator and robot socket reset: nobody can send a stop through it
        pump(lambda: gui.app.fleet.roster_lost is not None, 15, "the window to notice the central server")
        # Nothing reaches the robots any more; each one's own watchdog ends the drive.
        pump(lambda: all(at(central, n)[3] == 0 for n in central.sims), 10, "every robot to stop")
        idle(1.5)  # whatever else the window would still say
        gui.shot("central-lost")
        told = [text for _t, _l, text in gui.window.banners.history]
        lost = [text for text in told if "robot list" in text]
        assert len(lost) == 1, told
        links = [text for text in told if "link lost" in text or "lost their link" in text]
        assert links == [], f"the central server's end was said again per robot: {told}"
        assert len(gui.app.fleet) == 0
        assert all(at(central, n)[3] == 0 for n in central.sims)
        gui.keyup("Up")
        idle(0.3)
        gui.keydown("Up")  # a fresh press reaches no robot
        idle(1.0)
        assert all(at(central, n)[3] == 0 for n in central.sims)
    finally:
        gui.keyup("Up")
        gui.close()


def test_a_restarted_central_server_brings_the_robots_back_and_a_held_key_drives_none(
    screenshots: Path, central: CentralThread
) -> None:
    gui = open_central(screenshots, "central-restarted", central)
    try:
        gui.focus()
        gui.keydown("Up")
        first = gui.app.fleet.selected.value
        assert first is not None
        pump(lambda: at(central, first.name)[3] > 0, 10, f"{first.name} to drive")
        central.kill_central()
        pump(lambda: gui.app.fleet.roster_lost is not None, 15, "the window to notice the central server")
        pump(lambda: all(at(central, n)[3] == 0 for n in central.sims), 10, "every robot to stop")
        drives = {n: at(central, n)[4] for n in central.sims}
        central.restart_central()  # the key is still held, all along
        fleet = gui.app.fleet
        pump(lambda: len(fleet) == 3 and gui.app.fleet.roster_lost is None, 30, "the robots to come back")
        pump(lambda: all(s.state.connection.value.connected for s in fleet), 20, "every robot to connect")
        assert sorted(names(gui)) == sorted(central.sims)
        selected = fleet.selected.value
        assert selected is not None and selected is not first
        idle(1.5)  # the held key's auto-repeat, the new sessions' first ticks: nothing may drive
        gui.shot("central-back")
        assert {n: at(central, n)[4] for n in central.sims} == drives, "a robot drove without a fresh press"
        told = [text for _t, _l, text in gui.window.banners.history]
        assert sum("robot list is back" in text for text in told) == 1, told
        gui.keyup("Up")
        idle(0.3)
        gui.keydown("Up")  # a fresh press drives the selected robot again
        pump(lambda: at(central, selected.name)[3] > 0, 10, f"{selected.name} to drive after a fresh press")
    finally:
        gui.keyup("Up")
        gui.close()

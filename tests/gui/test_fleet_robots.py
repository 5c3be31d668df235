"""Three simulated robots in one window (``rtmu sim --robots 3``'s fleet, each server on its own thread).

Real window, real xdotool keys and clicks, real loopback servers; what is checked is what
the simulators did and what the window drew:

* the three robots are listed and drawn on the map, each in its colour;
* a click on a row selects that robot and a held key drives it alone — the other two
  stay exactly where they were, at their simulators;
* switching the selection while a key is held stops the first robot at once (not its
  watchdog) and the second does not move until a fresh press;
* one robot's server killed: its row says the link is lost and its marker goes grey,
  while another robot still updates on the map and the selected one still drives.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import gi
import numpy as np
import pytest

from rtmu.client.roster import Emit, RobotAdded, RobotEndpoint
from rtmu.fleet.sessions import RobotSession
from rtmu.settings.store import DirectRobot
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.multi import SimFleetThreads, fleet_configs
from rtmu.ui.application import RtmuApplication
from rtmu.ui.fleet_bind import FleetBinding
from rtmu.ui.options import GuiOptions
from rtmu.ui.overlays import STALE_RGB
from rtmu.ui.robot_list import row_text

from .harness import OFFICE_MAP, OPEN, Gui, idle, pump, register, scratch_dir

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402


@pytest.fixture
def sims() -> Iterator[list[SimThread]]:
    with SimFleetThreads(fleet_configs(SimConfig(port=0, map_path=OFFICE_MAP), 3)) as fleet:
        yield fleet.sims


def open_fleet(screenshots: Path, name: str, sims: list[SimThread]) -> Gui:
    robots = tuple(DirectRobot(f"robot{i + 1}", "127.0.0.1", sim.port) for i, sim in enumerate(sims))
    options = GuiOptions(
        fleet=robots, settings_path=scratch_dir("settings-") / "settings.toml", persist=False
    )
    gui = Gui.open(options, screenshots, name)
    fleet = gui.app.fleet
    pump(lambda: len(fleet) == 3, 10, "three robot sessions")
    pump(lambda: all(s.state.robot.value.numbers_at is not None for s in fleet), 15, "every robot's status")
    pump(lambda: all(s.state.map.value.state == "ready" for s in fleet), 20, "every robot's map")
    gui.wait_armed()
    gui.stage.fit()
    idle(0.3)
    return gui


def binding(gui: Gui) -> FleetBinding:
    assert gui.app.fleet_binding is not None
    return gui.app.fleet_binding


def session(gui: Gui, name: str) -> RobotSession:
    found = gui.app.fleet.named(name)
    assert found is not None
    return found


def pose(sim: SimThread) -> tuple[float, float, float]:
    snap = sim.snapshot()
    return (snap.x, snap.y, snap.th)


def mode(sim: SimThread) -> str:
    return str(sim.call(lambda: sim.server.robot.mode_name))


def drives(sim: SimThread) -> int:
    return int(sim.call(lambda: sim.server.robot.ratio_drives_received))


def watchdog_stops(sim: SimThread) -> int:
    return int(sim.call(lambda: sim.server.robot.watchdog_stops))


def colour_near(
    pixels: np.ndarray, xy: tuple[float, float], rgb: tuple[float, float, float], radius: int = 9
) -> int:
    """Pixels within ``radius`` of ``xy`` whose colour is close to ``rgb`` (0…1)."""
    x, y = round(xy[0]), round(xy[1])
    h, w, _ = pixels.shape
    patch = pixels[max(0, y - radius) : min(h, y + radius + 1), max(0, x - radius) : min(w, x + radius + 1)]
    target = np.array([c * 255 for c in rgb])
    return int((np.abs(patch.astype(int) - target).max(axis=2) < 40).sum())


def on_screen(gui: Gui, s: RobotSession) -> tuple[float, float]:
    r = s.state.robot.value
    return gui.stage.viewport.to_screen(r.x, r.y)


def click_row(gui: Gui, name: str) -> None:
    row = binding(gui).robot_list.row_of(session(gui, name))
    assert row is not None
    gui.click(row)
    pump(lambda: gui.app.fleet.selected.value is session(gui, name), 5, f"{name} to be selected")
    gui.wait_armed(session(gui, name))  # it drives on a key pressed once its guardian can stop it


def test_three_robots_are_listed_and_drawn_each_in_its_colour(
    screenshots: Path, sims: list[SimThread]
) -> None:
    gui = open_fleet(screenshots, "fleet-three-robots", sims)
    try:
        b = binding(gui)
        assert b.robot_list.get_visible() and b.robot_list.get_mapped()
        rows = [row_text(s) for s in gui.app.fleet]
        assert [r.name for r in rows] == ["robot1", "robot2", "robot3"]
        assert all(r.link.startswith("link ok") and r.battery.endswith("V") and not r.stale for r in rows), (
            rows
        )
        assert gui.window.subtitle_label.get_text().startswith("robot1")
        gui.shot("three-robots")
        pixels = gui.stage_pixels()
        for s in gui.app.fleet:
            assert colour_near(pixels, on_screen(gui, s), b.colour(s)) > 20, (
                f"{s.name} is not drawn in its colour"
            )
        colours = {b.colour(s) for s in gui.app.fleet}
        assert len(colours) == 3
        # The three robots share one map file (same getMapId): it was downloaded once, not three times.
        shared = [s.runner.session.maps.downloads_shared for s in gui.app.fleet if s.runner.session]
        assert sum(shared) == 2, shared
        datas = {id(s.state.map.value.data) for s in gui.app.fleet}
        assert len(datas) == 1, "each robot holds its own copy of the same map"
    finally:
        gui.close()


def test_a_clicked_robot_drives_alone_and_the_others_stay_still(
    screenshots: Path, sims: list[SimThread]
) -> None:
    gui = open_fleet(screenshots, "fleet-drive-one", sims)
    try:
        before = [pose(sim) for sim in sims]
        click_row(gui, "robot2")
        assert gui.window.subtitle_label.get_text().startswith("robot2")
        gui.keydown("Up")
        pump(lambda: sims[1].snapshot().vel > 0, 5, "robot2 to move")
        idle(0.8)
        gui.shot("robot2-driving")
        gui.keyup("Up")
        pump(lambda: sims[1].snapshot().vel == 0, 5, "robot2 to stop after the release")
        assert math.dist(pose(sims[1])[:2], before[1][:2]) > 50, "robot2 did not drive"
        for i in (0, 2):
            assert pose(sims[i]) == before[i], f"robot{i + 1} moved while robot2 was driven"
        assert drives(sims[2]) == 0, "robot3 was sent a drive command"
        assert mode(sims[0]) == "stop", "robot1 was not left stopped (the switch sends it zero ratios + stop)"
    finally:
        gui.keyup("Up")
        gui.close()


def test_switching_while_a_key_is_held_stops_the_first_and_the_second_waits(
    screenshots: Path, sims: list[SimThread]
) -> None:
    gui = open_fleet(screenshots, "fleet-switch-held", sims)
    try:
        gui.keydown("Up")
        pump(lambda: mode(sims[0]) == "ratioDrive" and sims[0].snapshot().vel > 0, 5, "robot1 to drive")
        watchdog = watchdog_stops(sims[0])
        click_row(gui, "robot2")  # the key is still down
        # Ours, not ARIA's 2 s watchdog: told by the watchdog's own count, not by a clock.
        pump(lambda: mode(sims[0]) == "stop", 3, "robot1's stop")
        assert watchdog_stops(sims[0]) == watchdog, "the watchdog stopped robot1, not the switch"
        start2 = pose(sims[1])
        idle(1.0)  # still held: auto-repeat must not reach the new robot
        gui.shot("switched-key-still-held")
        assert drives(sims[1]) == 0 and pose(sims[1]) == start2, "robot2 started without a fresh press"
        gui.keyup("Up")
        idle(0.2)
        gui.keydown("Up")  # a fresh press
        pump(lambda: sims[1].snapshot().vel > 0, 5, "robot2 to drive on a fresh press")
        gui.keyup("Up")
        assert mode(sims[0]) == "stop" and sims[0].snapshot().vel == 0
    finally:
        gui.keyup("Up")
        gui.close()


def test_one_killed_server_greys_its_robot_and_the_rest_carry_on(
    screenshots: Path, sims: list[SimThread]
) -> None:
    gui = open_fleet(screenshots, "fleet-one-killed", sims)
    try:
        b = binding(gui)
        third = session(gui, "robot3")
        second = session(gui, "robot2")
        where3 = on_screen(gui, third)
        sims[2].kill()
        # the row's link words follow the connection's state at the list's own pace (~150 ms)
        pump(lambda: row_text(third).stale, 10, "robot3's row to go stale")
        pump(
            lambda: "lost" in row_text(third).link or "reconnect" in row_text(third).link,
            5,
            "robot3 said lost",
        )
        sims[1].call(lambda: sims[1].server.world.wander())  # robot2 goes on moving by itself
        start2 = second.state.robot.value
        updates2 = b.drawn_updates.get("robot2", 0)
        pump(lambda: math.dist((second.state.robot.value.x, second.state.robot.value.y),
                               (start2.x, start2.y)) > 100, 10, "robot2's pose to update")  # fmt: skip
        gui.keydown("Up")
        pump(lambda: sims[0].snapshot().vel > 0, 5, "the selected robot to drive")
        gui.keyup("Up")
        idle(0.5)
        gui.shot("robot3-lost")
        assert b.drawn_updates.get("robot2", 0) > updates2, "robot2's new poses were not drawn"
        pixels = gui.stage_pixels()
        assert colour_near(pixels, where3, STALE_RGB) > 20, "robot3's marker is not greyed"
        assert colour_near(pixels, where3, b.colour(third)) == 0, "robot3 is still drawn in its live colour"
        row = b.robot_list.row_of(third)
        assert row is not None and row.has_css_class("robot-stale")
        assert not row_text(second).stale and not row_text(session(gui, "robot1")).stale
    finally:
        gui.keyup("Up")
        gui.close()


def test_a_narrow_window_folds_the_list_under_the_map_and_names_stay_plain_text(
    screenshots: Path, sims: list[SimThread]
) -> None:
    hostile = '<b>robot</b>\x1b[31m"2"'
    robots = (
        DirectRobot("robot1", "127.0.0.1", sims[0].port),
        DirectRobot(hostile, "127.0.0.1", sims[1].port),
    )
    options = GuiOptions(
        fleet=robots, settings_path=scratch_dir("settings-") / "settings.toml", persist=False
    )
    gui = Gui.open(options, screenshots, "fleet-narrow")
    try:
        b = binding(gui)
        gui.window.set_default_size(520, 480)
        pump(lambda: 0 < gui.window.get_width() < 560, 5, "the window to narrow")
        pump(lambda: b.robot_list.fold.get_visible(), 3, "the list to become a strip")
        assert gui.window.body.get_orientation() is Gtk.Orientation.VERTICAL
        row = b.robot_list.row_of(session(gui, hostile))
        assert row is not None
        assert row.name.get_text() == '<b>robot</b> [31m"2"' and not row.name.get_use_markup()
        gui.shot("narrow-strip")
        strip = b.robot_list.get_height()
        gui.click(b.robot_list.fold)
        pump(lambda: not b.robot_list.revealer.get_child_revealed(), 3, "the strip to fold")
        pump(lambda: b.robot_list.get_height() < strip, 3, "the map to take the room")
        gui.shot("narrow-folded")
        assert gui.stage.get_height() > 0
    finally:
        gui.close()


def test_a_one_robot_profile_shows_no_robot_list(screenshots: Path, sims: list[SimThread]) -> None:
    gui = Gui.start(screenshots, "fleet-of-one", "127.0.0.1", sims[0].port)
    try:
        assert gui.app.fleet_binding is None and len(gui.app.fleet) == 1
        body = gui.window.body
        assert body.get_first_child() is body.get_last_child(), "something beside the map of one robot"
        gui.shot("one-robot")
    finally:
        gui.close()


class LateRoster:
    """A roster that names its robots later than it starts, as a central server does: when the test
    says (:meth:`name_them`), not after a fixed delay a busy machine could outrun."""

    def __init__(self, endpoints: list[RobotEndpoint]) -> None:
        self.endpoints = endpoints
        self.closed = False
        self.emit: Emit | None = None

    def start(self, emit: Emit) -> None:
        self.emit = emit

    def name_them(self) -> None:
        assert self.emit is not None, "the window never started its roster"
        for endpoint in self.endpoints:
            if not self.closed:
                self.emit(RobotAdded(endpoint))

    def close(self) -> None:
        self.closed = True


def test_robots_a_roster_names_later_appear_and_the_first_is_shown(
    screenshots: Path, sims: list[SimThread]
) -> None:
    late = LateRoster([RobotEndpoint(f"robot{i + 1}", "127.0.0.1", sim.port) for i, sim in enumerate(sims)])
    options = GuiOptions(
        settings_path=scratch_dir("settings-") / "settings.toml", persist=False, connect=False
    )
    app = RtmuApplication(options)
    app.roster_for = lambda _profile: late  # type: ignore[method-assign]
    register(app)
    gui = Gui(app, screenshots, "fleet-late-roster")
    OPEN[id(gui)] = gui.close
    app.activate()
    try:
        pump(lambda: app.window is not None and app.window.get_mapped(), 10, "the window")
        pump(lambda: late.emit is not None, 10, "the window to start its roster")
        idle(0.3)  # nothing named yet: the window shows no robot and no list meanwhile
        assert len(app.fleet) == 0 and binding(gui).robot_list.get_visible() is False
        gui.shot("late-robots-none-yet")
        late.name_them()
        pump(lambda: len(app.fleet) == 3, 10, "the roster's robots")
        first = session(gui, "robot1")
        pump(lambda: gui.window.session is first, 5, "the first robot to be shown")
        pump(lambda: first.state.connection.value.connected, 10, "robot1 to connect")
        pump(lambda: gui.model.robot.value.numbers_at is not None, 10, "robot1's status in the window")
        # The list follows the roster at its own pace (at most every 150 ms): waited for, not assumed.
        pump(lambda: binding(gui).robot_list.get_visible(), 5, "the robot list to show the three")
        gui.shot("late-robots")
    finally:
        gui.close()

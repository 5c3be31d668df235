"""In a fleet, the selected robot is the one every widget commands — and only that one.

Two simulators, the real window, real keys: after Alt+2 selects robot 2, the camera head's keys,
live video and a layer switch reach robot 2's simulator and never robot 1's, and the Foxglove bridge
publishes robot 2; Alt+1 turns it all back. What each simulator heard is read from its own request
log (``SimServer.heard``), so no mock stands between the window and the robots.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from rtmu.client.video_session import CameraFeed
from rtmu.fleet.sessions import RobotSession
from rtmu.settings.store import DirectRobot
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.multi import SimFleetThreads, fleet_configs
from rtmu.ui.options import GuiOptions

from .harness import OFFICE_MAP, Gui, pump, scratch_dir

CAMERA_REQUESTS = ("getPicture", "sendVideo")
HEAD_MOVES = ("setCameraRel", "setCameraAbs")


def heard(sim: SimThread, since: int = 0) -> list[str]:
    """The data names robot ``sim`` heard, from request number ``since`` on."""
    return [h.name for h in sim.call(lambda: sim.server.heard.all())[since:]]


def count(sim: SimThread) -> int:
    return len(sim.call(lambda: sim.server.heard.all()))


def any_of(names: list[str], prefixes: tuple[str, ...]) -> bool:
    return any(n.startswith(prefixes) for n in names)


@pytest.fixture
def fleet_gui(screenshots: Path) -> Iterator[tuple[Gui, tuple[SimThread, ...]]]:
    with SimFleetThreads(fleet_configs(SimConfig(port=0, map_path=OFFICE_MAP, camera=True), 2)) as fleet:
        sims = fleet.sims
        robots = tuple(DirectRobot(f"robot{i + 1}", "127.0.0.1", s.port) for i, s in enumerate(sims))
        options = GuiOptions(
            fleet=robots, settings_path=scratch_dir("settings-") / "settings.toml", persist=False
        )
        gui = Gui.open(options, screenshots, "fleet-selected-robot")
        try:
            app_fleet = gui.app.fleet
            pump(lambda: len(app_fleet) == 2, 10, "two robot sessions")
            pump(lambda: all(s.state.map.value.state == "ready" for s in app_fleet), 20, "every robot's map")
            pump(lambda: all(s.state.robot.value.ptz is not None for s in app_fleet), 10, "both camera heads")
            pump(lambda: all(s.state.drawings.value.layers for s in app_fleet), 10, "both robots' drawings")
            yield gui, sims
        finally:
            gui.close()


def select(gui: Gui, number: int) -> RobotSession:
    """Alt+NUMBER; returns once the window shows that robot and the other's video loop has ended
    (a picture asked just before the switch may still be on its way: it is not counted)."""
    fleet = gui.app.fleet
    gui.key(f"alt+{number}")
    pump(lambda: fleet.selected.value is fleet.sessions.value[number - 1], 3, f"Alt+{number}")
    pump(lambda: gui.window.robot.session is fleet.selected.value, 3, "the window to show it")
    other = fleet.sessions.value[2 - number]
    pump(lambda: not video_running(other), 3, "the other robot's video to stop")
    return fleet.sessions.value[number - 1]


def video_running(session: RobotSession) -> bool:
    inner = session.runner.session
    if inner is None:
        return False
    return bool(session.runner.call(lambda: inner.feed(CameraFeed).feed is not None))


def shown(session: RobotSession, layer: str) -> bool:
    return next(d for d in session.state.drawings.value.layers if d.name == layer).shown


def toggle_bridge(gui: Gui) -> None:
    action = gui.window.lookup_action("foxglove")
    assert action is not None
    action.activate(None)


def test_the_camera_head_video_layers_and_bridge_follow_the_selected_robot(
    fleet_gui: tuple[Gui, tuple[SimThread, ...]],
) -> None:
    gui, (sim1, sim2) = fleet_gui
    window = gui.window
    for number, chosen, other in ((2, sim2, sim1), (1, sim1, sim2)):
        session = select(gui, number)
        marks = (count(chosen), count(other))

        # The camera page and its head: Escape shows it, Ctrl+Right pans.
        if window.stack.get_visible_child_name() != "camera":
            gui.key("Escape")
        pump(lambda: window.stack.get_visible_child_name() == "camera", 3, "the camera page")
        gui.key("ctrl+Right")
        pump(
            lambda c=chosen, m=marks[0]: any_of(heard(c, m), HEAD_MOVES), 5, f"robot {number}'s head to move"
        )

        # Live video: V plays it; pictures are asked of the selected robot.
        if not window.live.live:
            gui.key("v")
        pump(
            lambda c=chosen, m=marks[0]: any_of(heard(c, m), CAMERA_REQUESTS), 5, f"robot {number}'s pictures"
        )
        gui.shot(f"robot{number}-camera")

        # A layer switched off and on again: the drawing is asked for again, of this robot.
        gui.key("Escape")
        pump(lambda: window.stack.get_visible_child_name() == "map", 3, "the map page")
        layer = next(d.name for d in session.state.drawings.value.layers if d.may_toggle and d.drawable)
        for topic in window.banners.topics():  # banners may lie over the panel (issue 21's layout part)
            window.banners.dismiss(topic)
        window.layers.open()
        pump(lambda n=layer: n in window.layers.buttons, 3, "the layers panel rows")
        gui.shot(f"robot{number}-layers")
        gui.click(window.layers.buttons[layer])
        pump(lambda s=session, n=layer: not shown(s, n), 3, "the layer off")
        asked = count(chosen)
        gui.click(window.layers.buttons[layer])
        pump(
            lambda c=chosen, a=asked, n=layer: n in heard(c, a), 5, f"robot {number} asked for {layer} again"
        )
        window.layers.close()

        # The bridge publishes the selected robot (started once; it follows the selection).
        if window.foxglove.bridge is None:
            window.foxglove.port = 0  # any free port: 8765 may be taken on this machine
            toggle_bridge(gui)
            pump(lambda: window.foxglove.bridge is not None, 5, "the Foxglove bridge")
        assert window.foxglove.session is session
        assert session.runner.on_publish is not None

        # Nothing of it reached the other robot: no head move, no picture, no layer request.
        theirs = heard(other, marks[1])
        assert not any_of(theirs, HEAD_MOVES), f"robot {3 - number}'s head moved: {theirs}"
        assert not any_of(theirs, CAMERA_REQUESTS), f"robot {3 - number} was asked for pictures"
        assert layer not in theirs, f"robot {3 - number} was asked for {layer}"
    toggle_bridge(gui)

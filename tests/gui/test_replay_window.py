"""``rtmu replay``: the real window on a recording: the robot where the file had it, pause, scrub, no drive.

A session against the simulator is recorded first (the window's own recorder, a real
drive). The window then opens on that file: it plays, the robot is drawn (pixels of the
stage) at the pose the file's ``/robot/pose`` channel holds for that moment, a real click
pauses, a real click on the timeline goes back (the session is rebuilt from the start),
and a held drive key, the STOP button and the D-pad's way in send nothing and say "replay".
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

from recorder.poses import recorded_pose_at
from recorder.simsession import hold, recorded_session
from rtmu.model.observables import Phase
from rtmu.recorder.replay import PacedLink
from rtmu.ui.options import GuiOptions
from rtmu.ui.overlays import ROBOT_RGB
from rtmu.values.state import MapPhase

from .harness import Gui, idle, pump, scratch_dir

pytestmark = pytest.mark.gui


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    directory = tmp_path_factory.mktemp("replay-window")
    with recorded_session(directory) as (session, ui, _view, _sim):
        ui.wait_for(lambda: session.state.map.value.state is MapPhase.READY, timeout=15)
        time.sleep(0.5)
        hold(ui, session, "forward", 2.5)
        time.sleep(0.5)
        ui.drain()
    (path,) = directory.glob("*.mcap")
    return path


def robot_blue_near(gui: Gui, x_mm: float, y_mm: float, radius: int = 6) -> int:
    """How many pixels around the world point look like the robot's body colour."""
    pixels = gui.stage_pixels().astype(int)
    sx, sy = (round(v) for v in gui.stage.viewport.to_screen(x_mm, y_mm))
    patch = pixels[max(0, sy - radius) : sy + radius + 1, max(0, sx - radius) : sx + radius + 1]
    blue = np.array([round(c * 255) for c in ROBOT_RGB])
    return int((np.abs(patch - blue).sum(axis=2) < 90).sum())


def says_replay(gui: Gui) -> bool:
    banners = gui.window.banners
    return any("replay" in (banners.text(t) or "").lower() for t in banners.topics())


def test_replay_draws_the_recorded_robot_pauses_scrubs_and_never_drives(
    recording: Path, screenshots: Path
) -> None:
    options = GuiOptions(replay=recording, settings_path=scratch_dir("settings-") / "s.toml", persist=False)
    gui = Gui.open(options, screenshots, "replay-window", connect=False)
    try:
        app = gui.app
        bar = app.replay_bar
        assert bar is not None
        replayer = app.fleet.selected.value.runner.opener.__self__  # type: ignore[union-attr]
        assert "REPLAY" in gui.window.title_label.get_text()
        bar.set_speed(8.0)
        pump(lambda: gui.phase is Phase.CONNECTED, 10, "the replay's session")
        pump(lambda: gui.model.map.value.state == "ready", 20, "the recorded map")
        link = replayer.link
        assert isinstance(link, PacedLink)
        pump(lambda: link.exhausted, 30, "the end of the recording")
        idle(0.5)
        gui.stage.set_follow(False)
        idle(0.3)
        robot = gui.model.robot.value
        end = recorded_pose_at(recording, link.delivered_ns)
        assert (round(robot.x), round(robot.y)) == end
        assert end[0] > 300, "the recording drove forward"
        gui.shot("replay-at-end")
        assert robot_blue_near(gui, *end) > 10, "the robot is drawn where the recording left it"

        # A real click pauses (the clock stops), a real click on the timeline goes back a quarter in.
        gui.click(bar.play_button)
        pump(lambda: not bar.clock.playing, 3, "the replay to pause")
        x, y = gui.centre_on_surface(bar.timeline)
        width = bar.timeline.get_width()
        xid = str(gui.xid())
        gui.xdotool("mousemove", "--window", xid, str(x - width // 2 + width // 5), str(y), "click", "1")
        pump(lambda: replayer.opened == 2, 5, "the session rebuilt from the start")
        back = replayer.link
        assert isinstance(back, PacedLink) and back is not link
        target = bar.clock.now_ns()
        assert target < link.delivered_ns
        due = sum(1 for c in replayer.recorded.chunks if c.at_ns <= target)
        pump(lambda: back.position >= due, 20, "the replay to reach the scrubbed time")
        idle(0.5)
        assert back.position == due, "paused: nothing after the scrubbed time"
        robot = gui.model.robot.value
        there = recorded_pose_at(recording, back.delivered_ns)
        assert (round(robot.x), round(robot.y)) == there
        assert there[0] < end[0] - 200
        gui.shot("replay-scrubbed-back")
        assert robot_blue_near(gui, *there) > 10, "the robot is drawn where the recording had it then"
        assert robot_blue_near(gui, *end) == 0, "and no longer where it ended"
        assert not gui.window.connect_button.get_visible(), "the header offers Disconnect in a replay"

        # Nothing drives: a held arrow key and the STOP button send nothing and say "replay".
        written, refused = back.written, back.refused
        banners = gui.window.banners
        banners.dismiss_all()
        gui.focus()
        gui.keydown("Up")
        idle(0.6)
        gui.keyup("Up")
        pump(lambda: says_replay(gui), 3, "a banner saying replay for the drive key")
        banners.dismiss_all()
        gui.click(gui.window.stop_button)
        pump(lambda: says_replay(gui), 3, "a banner saying replay for STOP")
        idle(0.5)
        assert not gui.window.controller.held
        lease = gui.app.fleet.selected.value.runner.lease  # type: ignore[union-attr]
        assert lease.view(time.monotonic()).generation == 0, "no drive lease was ever granted"
        window = gui.window
        window.activate_action("win.dpad", None)
        pump(lambda: window.dpad.get_visible() and window.dpad.get_mapped(), 3, "the D-pad")
        banners.dismiss_all()
        x, y = gui.centre_on_surface(window.dpad.pads["drive_forward"])  # pressed all the same
        gui.xdotool(
            "mousemove", "--window", xid, str(x), str(y), "mousedown", "1", "sleep", "0.4", "mouseup", "1"
        )
        pad = window.dpad.pads["drive_forward"]
        assert not pad.get_sensitive() and "Replay" in (pad.get_tooltip_text() or "")  # greyed, saying why
        assert lease.view(time.monotonic()).generation == 0
        assert (back.written, back.refused) == (written, refused), "the replay link saw no write at all"
        gui.shot("replay-drive-refused")

        # One step on (a real click): only the clock moves, no rebuild; the next second is shown.
        before = back.position
        gui.click(bar.forward)
        pump(lambda: back.position > before, 5, "the next second to be shown")
        assert replayer.opened == 2 and not bar.clock.playing

        # Played on after the seek back, with the network thread busy for a second (as a rebuild from
        # the first byte keeps it): a replay sends nothing, so no "stops are not going out" alarm.
        topics: set[str] = set()
        bar.set_speed(1.0)
        gui.click(bar.play_button)
        pump(lambda: bar.clock.playing, 3, "the replay to play")
        runner = gui.app.fleet.selected.value.runner
        assert runner is not None
        runner.submit(lambda: time.sleep(1.2))
        end_at = time.monotonic() + 2.0
        stale: list[object] = []

        def watch() -> bool:
            topics.update(gui.window.banners.topics())
            cell = gui.window.toolbar.cells["x"]
            if cell.stale:
                stale.append((gui.model.health.value.level, gui.phase, cell.get_tooltip_text()))
            return time.monotonic() > end_at

        pump(watch, 5, "2 s")
        assert not stale, f"stale markers while the recording plays on: {stale[:3]}"
        assert "loop" not in topics, "a replay raised the network-thread alarm"
    finally:
        gui.close()

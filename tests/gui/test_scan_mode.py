"""Scanning for a map in the real window: name, Start, drive by hand, loop tags, Stop, download — real input.

Real window, real simulator writing its ``.2d`` into a folder of this test's own, real X keys and
clicks. Checked where it lands: the banner's running time and distance, the loop tags and the poses
in the downloaded log (read by the tests' own ``.2d`` reader), a turn asked while scanning refused
with the reason and never sent, a bad scan name said in the dialog. STOP works in every state this
adds: Space while the dialog has the keys, Space and the STOP button while driving during a scan,
and Space after the scan ended.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest

from client.scanlog_reader import Reading, Tag, read_scan_log
from rtmu.package_data import project_map
from rtmu.sim import SimThread
from rtmu.ui.scan_mode import ScanBar, ScanDialog
from rtmu.values.target import Target
from simulators import running

from .harness import Gui, idle, pump, scratch_dir
from .stop_paths import StopCycle, owned_windows
from .test_config_page import click, type_into


@pytest.fixture
def robot_files() -> Path:
    return scratch_dir("robot-scans-")


@pytest.fixture
def sim(robot_files: Path) -> Iterator[SimThread]:
    with running(map_path=project_map("office.map"), files_dir=robot_files, seed=1) as s:
        yield s


def bar_of(gui: Gui) -> ScanBar:
    return gui.window.commissioning.scan_bar


def open_dialog(gui: Gui) -> ScanDialog:
    gui.window.activate_action("win.scan", None)
    bar = bar_of(gui)
    pump(lambda: bar.dialog is not None and bar.dialog.get_mapped(), 5, "the scan dialog")
    assert bar.dialog is not None
    return bar.dialog


def drive_up_then_space(gui: Gui, cycle: StopCycle, what: str, seconds: float = 1.5) -> None:
    """Hold Up (real key) until the robot drives, a while longer, then Space stops it."""
    gui.focus()
    gui.keydown("Up")
    try:
        pump(cycle.driven, 20, f"a held Up to drive ({what})")  # generous: a loaded machine
        idle(seconds)
        cycle.space_stops(what)
    finally:
        gui.keyup("Up")
    pump(lambda: not cycle.driven(), 5, f"the robot to stop ({what})")


def test_scan_drive_tag_stop_and_download_with_stop_working_throughout(
    gui: Gui, sim: SimThread, robot_files: Path
) -> None:
    from gi.repository import GdkX11, Gio

    cycle = StopCycle(gui, sim)
    bar = bar_of(gui)
    assert not bar.get_reveal_child()
    dialog = open_dialog(gui)
    # a name that cannot be a file is said in the dialog, nothing is sent
    type_into(gui, dialog.name_entry, "../up", leave=False)
    click(gui, dialog.start_button)
    pump(lambda: "cannot name a scan" in dialog.reason.get_text(), 5, "the refusal of the name")
    assert not gui.model.scan.value.scanning and not list(robot_files.iterdir())
    gui.render(dialog, gui.shots / f"{gui.name}-bad-name.png")
    # Space stops while the dialog holds the keys (in its text field)
    gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(dialog.get_surface())))
    before = cycle.stops()
    gui.key("space")
    pump(lambda: cycle.stops() > before, 5, "Space in the scan dialog to stop the robot")
    assert dialog.name_entry.get_text() == "../up"  # Space stopped; it typed nothing

    type_into(gui, dialog.name_entry, "Hall-2", leave=False)
    gui.key("Return")  # Start is the default
    pump(lambda: gui.model.scan.value.scanning, 10, "the scan to start")
    pump(lambda: not dialog.get_visible(), 5, "the dialog to close")
    pump(bar.get_reveal_child, 5, "the scanning banner")
    assert gui.model.scan.value.file_name == "hall-2.2d"
    assert (robot_files / "hall-2.2d").is_file()

    # drive by hand: the banner counts time and metres; Space stops
    drive_up_then_space(gui, cycle, "while scanning")
    pump(lambda: bar.progress is not None and bar.progress.metres > 0.2, 5, "metres driven in the banner")
    idle(0.6)
    text = bar.label.get_text()
    assert re.fullmatch(r"Scanning hall-2\.2d… \d+:\d\d, \d+\.\d m driven", text), text
    gui.shot("scanning")
    from gi.repository import Gtk

    minimum = bar.measure(Gtk.Orientation.HORIZONTAL, -1)[0]
    assert minimum <= 360, minimum  # the bar fits a portrait phone (ui.layout's narrowest window)

    # the loop tags, with real clicks
    assert not bar.loop_end.get_sensitive()
    click(gui, bar.loop_start)
    pump(lambda: bar.loop_end.get_sensitive(), 5, "Loop start to be taken")
    drive_up_then_space(gui, cycle, "inside the loop", seconds=0.8)
    click(gui, bar.loop_end)
    pump(lambda: "loop end tagged" in bar.label.get_text(), 5, "Loop end to be taken")

    # a turn asked with its key is refused with the reason, and never sent
    heading = gui.model.robot.value.th
    gui.focus()
    gui.key("shift+Left")
    pump(
        lambda: any("not while scanning" in t for _topic, _lvl, t in gui.window.banners.history), 5, "refusal"
    )
    idle(1.0)
    assert abs(gui.model.robot.value.th - heading) < 1.0 and cycle.mode() != "turnByAngle"
    gui.shot("turn-refused")

    # the STOP button stops a drive during the scan
    gui.focus()
    gui.keydown("Up")
    try:
        pump(cycle.driven, 8, "a held Up to drive before the STOP button")
        before = cycle.stops()
        gui.click(gui.window.stop_button)
        pump(lambda: cycle.stops() > before, 5, "the STOP button to stop the robot")
    finally:
        gui.keyup("Up")

    # Stop the scan; the bar offers the download
    click(gui, bar.stop_scan)
    pump(lambda: not gui.model.scan.value.scanning, 10, "the scan to end")
    pump(lambda: bar.download.get_visible(), 5, "Download the scan…")
    assert gui.model.scan.value.last_file == "hall-2.2d"
    gui.shot("scan-ended")
    drive_up_then_space(gui, cycle, "after the scan ended", seconds=0.3)

    # Download the scan… into a folder picked in the chooser (its path typed, then Select)
    local = scratch_dir("scans-here-")
    click(gui, bar.download)
    pump(lambda: bar.chooser is not None and bar.chooser.get_mapped(), 5, "the folder chooser")
    chooser = bar.chooser
    assert chooser is not None
    gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(chooser.get_surface())))
    gui.key("ctrl+l")
    idle(0.3)
    gui.xdotool("type", "--delay", "20", str(local) + "/")
    idle(0.5)
    gui.screen_shot("download-chooser")
    select = chooser.get_widget_for_response(-3)  # Gtk.ResponseType.ACCEPT
    click(gui, select)
    pump(lambda: bar.downloads == 1, 20, "the scan's download")
    assert "Saved the scan to" in bar.label.get_text()
    assert bar.transfers_shown >= 1  # the download's progress bar showed while it lasted
    pump(lambda: not bar.transfer_bar.get_parent().get_visible(), 5, "the progress bar gone once done")  # type: ignore[union-attr]
    gui.shot("scan-downloaded")
    log = read_scan_log((local / "hall-2.2d").read_text(encoding="latin-1"))
    readings = [r for r in log.order if isinstance(r, Reading)]
    tags = [t for t in log.order if isinstance(t, Tag)]
    assert log.ended and len(readings) >= 3  # a reading each time the robot moved far enough
    assert [t.text.split()[:2] for t in tags] == [["loop", "start"], ["loop", "stop"]]
    xs = [r.pose[0] for r in readings]
    assert max(xs) - min(xs) > 200  # the driven path is in the log
    assert [r.time for r in readings] == sorted(r.time for r in readings)

    # downloading again asks before replacing
    click(gui, bar.download)
    pump(lambda: bar.chooser is not None and bar.chooser.get_mapped(), 5, "the folder chooser again")
    again = bar.chooser
    assert again is not None
    again.set_current_folder(Gio.File.new_for_path(str(local)))  # the chooser's own typing was shown above
    click(gui, again.get_widget_for_response(-3))
    pump(lambda: bar.confirm is not None and bar.confirm.get_mapped(), 5, "the replace question")
    assert "“hall-2.2d” already exists" in bar.confirm.question.get_text()  # type: ignore[union-attr]
    click(gui, bar.confirm.cancel_button)  # type: ignore[union-attr]
    pump(lambda: not owned_windows(gui.window), 5, "the question to close")
    assert bar.downloads == 1

    click(gui, bar.dismiss)
    pump(lambda: not bar.get_reveal_child(), 5, "the banner to go")


def test_a_scan_started_elsewhere_shows_its_bar_and_guards_motion(
    screenshots: Path, sim: SimThread, robot_files: Path
) -> None:
    from client.servers import run
    from rtmu.client.connection import AriaClient
    from rtmu.client.scan import start_scan, stop_scan

    async def begin() -> None:
        c = AriaClient()
        await c.connect(Target("127.0.0.1", sim.port), timeout=10)
        try:
            await start_scan(c, "early")
        finally:
            await c.disconnect()

    run(begin(), 20)  # a scan already running before the window connects
    gui = Gui.start(screenshots, "test_scan_started_elsewhere", "127.0.0.1", sim.port)
    try:
        bar = bar_of(gui)
        pump(bar.get_reveal_child, 10, "the bar for a scan running at login")
        assert "Scanning early" in bar.label.get_text()
        assert "running before this connection" in bar.label.get_text(), gui.model.scan.value
        gui.shot("scan-running-at-login")
        dialog = open_dialog(gui)  # a second scan cannot be started: said, Start greyed
        assert not dialog.start_button.get_sensitive()
        assert "a scan is already running" in dialog.reason.get_text()
        dialog.close()

        async def end() -> None:
            c = AriaClient()
            await c.connect(Target("127.0.0.1", sim.port), timeout=10)
            try:
                await stop_scan(c)
            finally:
                await c.disconnect()

        run(end(), 20)  # another client ends it: the bar offers its download
        pump(lambda: bar.download.get_visible(), 10, "the ended scan offered")
        assert gui.model.scan.value.last_file.startswith("early")
        gui.shot("scan-ended-elsewhere")
    finally:
        gui.close()

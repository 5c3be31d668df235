"""The robot's files page in the real window: list, open a folder, download, upload, delete — real input.

Real window, real simulator sharing a folder of this test's own, real X clicks and keys. What is
checked is on disk on both sides: the downloaded bytes, a local file left alone when the operator
declines to replace it, the uploaded file in the robot's folder, a deleted file gone; the refusal of
a file that vanished behind the page's back said in words; a user without file access sees every
feature greyed with the reason. Space stops the robot while the page (and its confirmation) has
the keyboard.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from rtmu.package_data import project_map
from rtmu.sim import SimConfig, SimThread
from rtmu.ui.confirm import Confirm
from rtmu.ui.files_page import FilesPage
from rtmu.values.commission import Direction, Transfer, TransfersState
from simulators import running

from .harness import Gui, LoopProbe, idle, pump, scratch_dir
from .stop_paths import StopCycle, owned_windows
from .test_config_page import click, type_into

BIG = 24 * 1024 * 1024


@pytest.fixture
def robot_files() -> Path:
    root = scratch_dir("robot-files-")
    (root / "maps").mkdir()
    (root / "maps" / "Office.map").write_bytes(project_map("office.map").read_bytes())
    (root / "big.bin").write_bytes(bytes(range(256)) * (BIG // 256))
    (root / "notes.txt").write_text("hello\n")
    return root


@pytest.fixture
def sim(robot_files: Path) -> Iterator[SimThread]:
    with running(map_path=project_map("office.map"), files_dir=robot_files, seed=1) as s:
        yield s


def open_page(gui: Gui) -> FilesPage:
    gui.window.activate_action("win.files", None)
    pump(lambda: isinstance(gui.window.commissioning.files_page, FilesPage), 5, "the files page")
    page = gui.window.commissioning.files_page
    assert page is not None
    pump(lambda: page.get_mapped() and page.listings >= 1, 15, "the first listing")
    return page


def row_named(page: FilesPage, name: str):  # type: ignore[no-untyped-def]
    index = [e.name for e in page.shown].index(name)
    return page.rows.get_row_at_index(index)


def double_click(gui: Gui, widget) -> None:  # type: ignore[no-untyped-def]
    from gi.repository import GdkX11

    x, y = gui.centre_on_surface(widget)
    xid = str(GdkX11.X11Surface.get_xid(widget.get_native().get_surface()))
    gui.xdotool("mousemove", "--window", xid, str(x), str(y))
    idle(0.15)
    gui.xdotool("click", "--repeat", "2", "--delay", "80", "1")


def confirmation(page: FilesPage) -> Confirm:
    pump(lambda: page.confirm is not None and page.confirm.get_mapped(), 5, "the confirmation")
    assert page.confirm is not None
    return page.confirm


def test_browse_download_replace_upload_and_delete_with_real_input(
    gui: Gui, sim: SimThread, robot_files: Path
) -> None:
    page = open_page(gui)
    names = [e.name for e in page.shown]
    assert names == ["maps", "big.bin", "notes.txt"]  # folders first, then files
    gui.render(page, gui.shots / f"{gui.name}-listing.png")
    # a folder opens on a double click, Up goes back
    double_click(gui, row_named(page, "maps"))
    pump(lambda: page.folder == "maps" and [e.name for e in page.shown] == ["Office.map"], 10, "maps/")
    assert "maps" in page.path_label.get_text()
    gui.render(page, gui.shots / f"{gui.name}-maps.png")
    seen = page.listings
    click(gui, page.up_button)
    pump(lambda: page.folder == "" and page.listings > seen, 10, "back up")

    # a download with progress, into a folder typed by the operator
    local = scratch_dir("downloads-")
    type_into(gui, page.local_entry, str(local))
    click(gui, row_named(page, "big.bin"))
    pump(lambda: page.download_button.get_sensitive(), 3, "Download for a file")
    bars: list[str] = []
    unobserve = gui.model.transfers.observe(lambda _o, new: bars.extend(t.remote for t in new.active))
    click(gui, page.download_button)
    pump(lambda: page.downloads == 1, 60, "the download")
    unobserve()
    assert (local / "big.bin").read_bytes() == (robot_files / "big.bin").read_bytes()
    assert "big.bin" in bars  # the transfer was shown while it ran
    assert "Downloaded big.bin" in page.status.get_text()
    gui.render(page, gui.shots / f"{gui.name}-downloaded.png")
    # how a transfer under way is drawn (the loopback download above is over too soon to catch)
    half = Transfer(Direction.DOWNLOAD, "big.bin", str(local / "big.bin"), BIG // 2, BIG)
    gui.model.transfers.set(TransfersState((half,)))
    bar = page.progress.get_first_child()
    assert bar is not None and bar.get_fraction() == 0.5 and "12.6 MB of 25.2 MB" in bar.get_text()
    gui.render(page, gui.shots / f"{gui.name}-progress.png")
    gui.model.transfers.set(TransfersState())
    assert page.progress.get_first_child() is None

    # downloading again asks before replacing; Cancel leaves the local file as it was
    (local / "big.bin").write_bytes(b"mine")
    click(gui, page.download_button)
    ask = confirmation(page)
    assert "“big.bin” already exists" in ask.question.get_text() and str(local) in ask.question.get_text()
    gui.render(ask, gui.shots / f"{gui.name}-replace.png")
    click(gui, ask.cancel_button)
    pump(lambda: not ask.get_mapped(), 5, "the confirmation to close")
    idle(0.5)
    assert (local / "big.bin").read_bytes() == b"mine" and page.downloads == 1

    # an upload through the file chooser, its path typed (ctrl+L) and taken with Return
    mine = local / "fresh.txt"
    mine.write_text("from the operator\n")
    click(gui, page.upload_button)
    pump(lambda: getattr(page, "chooser", None) is not None and page.chooser.get_mapped(), 5, "the chooser")
    from gi.repository import GdkX11

    gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(page.chooser.get_surface())))
    gui.key("ctrl+l")
    idle(0.3)
    gui.xdotool("type", "--delay", "20", str(mine))
    idle(0.3)
    gui.screen_shot("upload-chooser")
    gui.key("Return")
    pump(lambda: (robot_files / "fresh.txt").is_file(), 20, "the upload on the robot")
    assert (robot_files / "fresh.txt").read_text() == "from the operator\n"
    pump(lambda: "fresh.txt" in [e.name for e in page.shown], 10, "the listing to show the upload")

    # delete asks, naming the file; Delete removes it from the robot and the listing
    click(gui, row_named(page, "notes.txt"))
    click(gui, page.delete_button)
    ask = confirmation(page)
    assert "“notes.txt”" in ask.question.get_text() and "Delete" in ask.question.get_text()
    gui.render(ask, gui.shots / f"{gui.name}-delete.png")
    click(gui, ask.yes_button)
    pump(lambda: not (robot_files / "notes.txt").exists(), 10, "the delete on the robot")
    pump(lambda: "notes.txt" not in [e.name for e in page.shown], 10, "the listing without it")

    # a file gone behind the page's back: the robot refuses, the page says so in words
    click(gui, row_named(page, "fresh.txt"))
    (robot_files / "fresh.txt").unlink()
    click(gui, page.delete_button)
    click(gui, confirmation(page).yes_button)
    pump(lambda: "failed" in page.status.get_text(), 10, "the refusal")
    assert page.status.has_css_class("error")
    gui.render(page, gui.shots / f"{gui.name}-refused.png")


def test_space_stops_while_the_files_page_and_its_confirmation_have_the_keys(
    gui: Gui, sim: SimThread
) -> None:
    page = open_page(gui)
    cycle = StopCycle(gui, sim)
    from gi.repository import GdkX11

    gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(page.get_surface())))
    pump(page.is_active, 5, "the page to have the keys")
    cycle.prove("the files page with the keyboard", dpad_here=False)
    page = open_page(gui)
    click(gui, row_named(page, "notes.txt"))
    click(gui, page.delete_button)
    ask = confirmation(page)
    gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(ask.get_surface())))
    pump(ask.is_active, 5, "the confirmation to have the keys")
    gui.screen_shot("confirmation-with-keys")
    cycle.prove("the delete confirmation with the keyboard", dpad_here=False)
    assert ask.answered is False  # closed by the cycle, never confirmed: the file is still there
    assert not owned_windows(gui.window)


def test_a_user_without_file_access_sees_every_feature_greyed_with_the_reason(
    screenshots: Path, robot_files: Path
) -> None:
    from gi.repository import GdkX11

    from .test_views import wait_for_window

    users = scratch_dir("users-") / "users.txt"
    users.write_text("UserInfoVersion1\nuser bob pw2 RobotInfo Movement Stop\n")
    config = SimConfig(port=0, map_path=None, users_path=users, files_dir=robot_files, seed=1)
    with SimThread(config) as sim:
        gui = Gui.start(screenshots, "test_files_greyed", "127.0.0.1", sim.port, connect=False, user="bob")
        try:
            gui.focus()
            gui.key("ctrl+o")
            prompt = wait_for_window("Password")
            gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(prompt.get_surface())))
            gui.xdotool("type", "--delay", "20", "pw2")
            gui.key("Return")
            gui.wait_connected()
            gui.window.activate_action("win.files", None)
            pump(lambda: gui.window.commissioning.files_page is not None, 5, "the files page")
            page = gui.window.commissioning.files_page
            assert page is not None
            pump(page.get_mapped, 5, "the page on screen")
            idle(0.3)
            reason = page.reason.get_text()
            assert "does not let its files be listed" in reason and "may not use it" in reason
            assert "does not accept files" in reason
            assert not page.upload_button.get_sensitive() and not page.refresh_button.get_sensitive()
            assert not page.download_button.get_sensitive() and not page.delete_button.get_sensitive()
            assert page.upload_button.get_tooltip_text() and not page.shown
            assert "failed" not in page.status.get_text()  # greyed, never an error
            gui.render(page, gui.shots / f"{gui.name}-greyed.png")
        finally:
            gui.close()


def test_a_map_on_the_robot_made_its_map_with_real_clicks(
    gui: Gui, sim: SimThread, robot_files: Path
) -> None:
    page = open_page(gui)
    double_click(gui, row_named(page, "maps"))
    pump(lambda: [e.name for e in page.shown] == ["Office.map"], 10, "maps/")
    (robot_files / "maps" / "Other.map").write_bytes((robot_files / "maps" / "Office.map").read_bytes())
    (robot_files / "maps" / "Broken.map").write_text("not a map\n")
    (robot_files / "maps" / "readme.txt").write_text("maps of the site\n")
    click(gui, page.refresh_button)
    pump(lambda: len(page.shown) == 4, 10, "the new files listed")
    click(gui, row_named(page, "readme.txt"))
    assert not page.use_map_button.get_sensitive()  # only a .map can be the map
    assert "select a .map file" in (page.use_map_button.get_tooltip_text() or "")
    generation = gui.model.map.value.generation

    # a file that is not a map: the robot refuses, its map stays
    click(gui, row_named(page, "Broken.map"))
    click(gui, page.use_map_button)
    click(gui, confirmation(page).yes_button)
    pump(lambda: "Switch map failed" in page.status.get_text(), 10, "the refusal")
    assert (
        "cannot be read as a map" in page.status.get_text() and gui.model.map.value.generation == generation
    )
    gui.render(page, gui.shots / f"{gui.name}-refused-map.png")

    click(gui, row_named(page, "Other.map"))
    click(gui, page.use_map_button)
    ask = confirmation(page)
    assert "“maps/Other.map” the robot's map" in ask.question.get_text()
    click(gui, ask.yes_button)
    pump(lambda: "now uses maps/Other.map" in page.status.get_text(), 15, "the switch")
    pump(
        lambda: gui.model.map.value.generation > generation and gui.model.map.value.state == "ready",
        15,
        "map",
    )
    assert "Other" in gui.model.map.value.name
    gui.render(page, gui.shots / f"{gui.name}-switched.png")
    gui.shot("window-after-switch")


def test_a_huge_folder_shows_a_bounded_page_and_a_hostile_name_is_refused_in_words(
    gui: Gui, sim: SimThread, robot_files: Path
) -> None:
    crowd = robot_files / "crowd"
    crowd.mkdir()
    for i in range(3000):
        (crowd / f"f{i:05d}.txt").touch()
    page = open_page(gui)
    seen = page.listings
    double_click(gui, row_named(page, "crowd"))
    pump(lambda: page.listings > seen, 30, "the crowd's listing")
    assert len(page.shown) == 1000 and "Showing the first 1000 of 3000 entries" in page.status.get_text()
    probe = LoopProbe()
    idle(0.5)
    probe.close()
    assert probe.beats > 0  # the main loop kept running
    gui.render(page, gui.shots / f"{gui.name}-crowd.png")

    (crowd / "bad\x1bname.txt").touch()  # a control character: the whole listing is refused, said in words
    seen = page.listings
    click(gui, page.refresh_button)
    pump(lambda: "List failed" in page.status.get_text(), 15, "the refusal of the listing")
    assert "not a plain file name" in page.status.get_text() and "\x1b" not in page.status.get_text()
    assert page.status.has_css_class("error") and not page.shown and page.listings == seen
    gui.render(page, gui.shots / f"{gui.name}-hostile-name.png")

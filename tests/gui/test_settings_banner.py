"""A hand-written settings file is used and what RTMU made of it is said in the window, not only on stderr.

Issue 22: the fleet example of the guide had no ``version = 1`` line; the file was moved aside and the
window opened on defaults with one line on stderr. Now such a file is read as version 1 — the fleet it
names opens — and the window's banner says so.
"""

from __future__ import annotations

from pathlib import Path

from rtmu.sim import SimThread
from rtmu.ui.options import GuiOptions
from simulators import simulator

from .harness import OFFICE_MAP, Gui, pump, scratch_dir

sim = simulator(map_path=OFFICE_MAP)


def test_a_fleet_file_without_its_version_line_opens_its_fleet_and_the_window_says_so(
    screenshots: Path, sim: SimThread
) -> None:
    settings = scratch_dir("settings-") / "settings.toml"
    text = f'[profiles.lab]\nrobots = [{{ name = "robot1", host = "127.0.0.1", port = {sim.port} }}]\n'
    settings.write_text(text)
    options = GuiOptions(profile="lab", settings_path=settings, persist=False)
    gui = Gui.open(options, screenshots, "settings-v1")
    try:
        banner = gui.window.banners.text("notice:settings")
        assert banner is not None and "read as version 1" in banner, banner
        pump(lambda: len(gui.app.fleet) == 1, 10, "the file's one robot")
        assert settings.read_text() == text, "the operator's file is neither moved aside nor rewritten"
        gui.shot("settings-without-version")
    finally:
        gui.close()

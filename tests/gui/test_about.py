"""Help ▸ About in the real window: the logo, the licence in words that read, and the debug information
support needs — versions, the robot's protocol strings, the last ``rtmu doctor`` (run for real against
the simulator first) — copied to the clipboard by one click on its button."""

from __future__ import annotations

import os
import subprocess
import sys

from rtmu import __version__
from rtmu.sim import SimThread
from simulators import simulator

from .harness import OFFICE_MAP, Gui, pump
from .stop_paths import owned_windows

sim = simulator(map_path=OFFICE_MAP, camera=False, seed=1)


def test_about_shows_the_logo_reads_right_and_copies_the_debug_information(gui: Gui, sim: SimThread) -> None:
    from gi.repository import Gtk

    doctor = subprocess.run(
        [sys.executable, "-m", "rtmu", "doctor", f"127.0.0.1:{sim.port}"],
        capture_output=True, text=True, timeout=120, env=dict(os.environ),
    )  # fmt: skip
    assert doctor.returncode == 0, doctor.stdout + doctor.stderr
    gui.wait_connected()
    assert gui.window.actions.activate("win.about")
    pump(lambda: any(isinstance(w, Gtk.AboutDialog) for w in owned_windows(gui.window)), 5, "About")
    about = next(w for w in owned_windows(gui.window) if isinstance(w, Gtk.AboutDialog))
    assert about.get_logo() is not None, "no logo: GTK shows a broken image"
    assert "The The" not in about.get_license() and "MIT License" in about.get_license()
    info = about.get_system_information()
    assert info.splitlines()[0] == f"rtmu {__version__}"
    assert f"robot: 127.0.0.1:{sim.port}" in info and "connected" in info
    assert "protocol string the server asked for:" in info and "server introduction tag:" in info
    assert "last rtmu doctor:" in info and "All steps passed" in info, info
    gui.screen_shot("about")

    got: list[str] = []
    gui.click(about.copy_button)  # type: ignore[attr-defined]
    pump(lambda: about.copy_button.get_label() == "Copied", 5, "the copy")  # type: ignore[attr-defined]
    clipboard = gui.window.get_clipboard()
    clipboard.read_text_async(None, lambda c, res: got.append(c.read_text_finish(res) or ""))
    pump(lambda: bool(got), 5, "the clipboard's text")
    assert got[0] == info
    about.close()

"""The connection settings dialog keeps its word (issue 21, "Settings"): real keys, the real window.

* A profile named after its address ("127.0.0.1:PORT") follows a port typed in the dialog.
* Save keeps the speed the operator chose since the profile was opened (70 %, not the profile's 50).
* Under ``--demo`` the window writes no settings by itself, but a Save does write the file.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

from gi.repository import GdkX11

from rtmu.sim import SimThread
from rtmu.ui.options import GuiOptions
from simulators import simulator

from .harness import OFFICE_MAP, Gui, pump, scratch_dir

sim = simulator(map_path=OFFICE_MAP, camera=False, seed=1)


def open_settings(gui: Gui):  # type: ignore[no-untyped-def]
    window = gui.window
    gui.focus()  # (no window manager gives the keyboard back to the window after a dialog)
    gui.key("ctrl+comma")
    pump(lambda: window.dialogs.settings is not None and window.dialogs.settings.get_mapped(), 3, "settings")
    dialog = window.dialogs.settings
    gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(dialog.get_surface())))
    pump(dialog.is_active, 5, "the dialog to have the keyboard")
    return dialog


def type_port(gui: Gui, dialog, port: int) -> None:  # type: ignore[no-untyped-def]
    dialog.port.grab_focus()
    pump(lambda: dialog.port.has_focus() or dialog.get_focus() is not None, 3, "the port field")
    gui.key("ctrl+a")
    gui.xdotool("type", "--delay", "40", str(port))
    pump(lambda: dialog.port.get_text() == str(port), 3, "the typed port")


def test_the_name_follows_the_port_and_save_keeps_the_speed(sim: SimThread, screenshots: Path) -> None:
    gui = Gui.start(screenshots, "settings-truthful", "127.0.0.1", sim.port)
    try:
        window = gui.window
        assert window.controller.profile.name == f"127.0.0.1:{sim.port}"
        assert gui.operator.speed.value.percent == 50
        gui.key("plus", "plus")
        pump(lambda: gui.operator.speed.value.percent == 70, 3, "the speed at 70 %")
        dialog = open_settings(gui)
        type_port(gui, dialog, sim.port + 1)
        assert dialog.profile_entry.get_text() == f"127.0.0.1:{sim.port + 1}", "the old port's name stayed"
        gui.render(dialog, gui.shots / f"{gui.name}-renamed.png")
        gui.key("Return")
        pump(lambda: not dialog.get_visible(), 3, "Save to close the dialog")
        profile = window.controller.profile
        assert (profile.name, profile.port) == (f"127.0.0.1:{sim.port + 1}", sim.port + 1)
        assert gui.operator.speed.value.percent == 70, "Save reset the speed"
        assert profile.speed == 70 and gui.app.settings.profiles[profile.name].speed == 70

        # A name the operator chose stays when the port changes.
        dialog = open_settings(gui)
        dialog.profile_entry.set_text("lab robot")
        type_port(gui, dialog, sim.port)
        assert dialog.profile_entry.get_text() == "lab robot"
        dialog.close()
        gui.focus()
        gui.key("space")  # the stop key still stops from the window afterwards
        pump(lambda: sim.snapshot().trans_ratio == 0, 3, "Space")
    finally:
        gui.close()


def test_demo_writes_nothing_by_itself_but_save_writes_the_file(sim: SimThread, screenshots: Path) -> None:
    path = scratch_dir("demo-settings-") / "settings.toml"
    options = GuiOptions(
        host="127.0.0.1", port=sim.port, demo=True, persist=False, settings_path=path, connect=True
    )
    gui = Gui.open(options, screenshots, "demo-save")
    try:
        assert not path.exists(), "the demo wrote its throw-away profile"
        dialog = open_settings(gui)
        dialog.profile_entry.set_text("demo robot")
        gui.key("Return")
        pump(lambda: not dialog.get_visible(), 3, "Save to close the dialog")
        pump(path.exists, 5, "the settings file")
        pump(lambda: "demo robot" in path.read_text(encoding="utf-8"), 5, "the saved profile in it")
        saved = tomllib.loads(path.read_text(encoding="utf-8"))
        assert "demo robot" in str(saved)
        gui.shot("demo-saved")
    finally:
        gui.close()

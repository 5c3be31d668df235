"""Large text and high contrast keep every control on screen: the header's buttons, the status that
decides whether to keep driving, and room for the map, at the smallest window the app is made for.

The desktop's large-text setting is GTK's ``gtk-xft-dpi`` (GNOME's text scaling 1.5 → 144 dpi), high
contrast its ``Default-hc`` theme; both are set on the real window's display as a desktop would, and
put back after. GDK_SCALE=2 (a HiDPI screen) is the process test beside it: the whole window drawn at
twice the pixels, STOP's red where it belongs.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from rtmu.sim import SimThread
from simulators import simulator

from .harness import OFFICE_MAP, Gui, idle, pump
from .process import screenshot, subscribed, wait, xdotool

LARGE_TEXT_DPI = int(96 * 1.5 * 1024)


sim = simulator(map_path=OFFICE_MAP, camera=True, seed=1)


def inside(gui: Gui, widget: object) -> bool:
    """The widget is mapped, has a size, and lies wholly inside the window."""
    from gi.repository import Graphene, Gtk

    assert isinstance(widget, Gtk.Widget)
    ok, bounds = widget.compute_bounds(gui.window)
    if not (widget.get_mapped() and ok and bounds.get_width() >= 8 and bounds.get_height() >= 8):
        return False
    whole = Graphene.Rect().init(0, 0, gui.window.get_width(), gui.window.get_height())
    return bool(whole.contains_rect(bounds))


def test_large_text_and_high_contrast_keep_every_control_on_screen(
    gui: Gui, capfd: pytest.CaptureFixture[str]
) -> None:
    from gi.repository import Gtk

    settings = Gtk.Settings.get_default()
    assert settings is not None
    before = (settings.get_property("gtk-xft-dpi"), settings.get_property("gtk-theme-name"))
    gui.wait_connected()
    try:
        settings.set_property("gtk-xft-dpi", LARGE_TEXT_DPI)
        settings.set_property("gtk-theme-name", "Default-hc")
        window = gui.window
        window.set_default_size(800, 480)
        idle(1.0)
        pump(lambda: window.get_width() <= 1000, 5, "the window at its small size")
        controls = {
            "STOP": window.stop_button, "Connect": window.connect_button, "menu": window.menu_button,
            "camera": window.camera_button, "Go to": window.goals_panel,
        }  # fmt: skip
        pump(lambda: all(inside(gui, w) for w in controls.values()), 5, "every header control inside")
        toolbar = window.toolbar
        for name in ("battery", "mode", "link"):
            assert toolbar.cells[name].get_visible() and inside(gui, toolbar.cells[name]), name
        assert toolbar.row.measure(Gtk.Orientation.HORIZONTAL, -1)[0] <= toolbar.get_width(), (
            "what shows fits"
        )
        assert window.stage.get_height() >= 150, "the map keeps room to be seen"
        gui.shot("large-text-high-contrast")
        complaints = [
            ln for ln in capfd.readouterr().err.splitlines() if re.search(r"-(WARNING|CRITICAL) \*\*", ln)
        ]
        assert not complaints, complaints
    finally:
        settings.set_property("gtk-xft-dpi", before[0])
        settings.set_property("gtk-theme-name", before[1])


def test_at_gdk_scale_2_the_window_is_drawn_at_twice_the_pixels_with_stop_in_view(
    sim: SimThread, tmp_path: Path, screenshots: Path
) -> None:
    env = dict(os.environ, GDK_SCALE="2", XDG_CONFIG_HOME=str(tmp_path))
    proc = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "--host", "127.0.0.1", "--port", str(sim.port)],
        env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        window = xdotool(
            "search", "--sync", "--onlyvisible", "--pid", str(proc.pid), "--name", "RTMU"
        ).split()[0]
        wait(lambda: subscribed(sim), 30, "the window to connect")
        geo = dict(
            line.split("=", 1)
            for line in xdotool("getwindowgeometry", "--shell", window).split()
            if "=" in line
        )
        width, height = int(geo["WIDTH"]), int(geo["HEIGHT"])
        assert width >= 2 * 360 and height >= 2 * 320, (width, height)  # the window's minimum, doubled
        shot = screenshots / "test_large_text-gdk-scale-2.png"

        def drawn_connected() -> bool:  # the battery gauge turns green once the status has come
            pixels = np.asarray(Image.open(screenshot(shot, window)).convert("RGB")).astype(int)
            toolbar = pixels[100:180, : min(900, width)]
            return bool(
                ((toolbar[..., 1] > 150) & (toolbar[..., 0] < 120) & (toolbar[..., 2] < 120)).sum() > 50
            )

        wait(drawn_connected, 30, "the window drawn connected", poll=0.5)
        pixels = np.asarray(Image.open(shot).convert("RGB")).astype(int)
        band = pixels[: min(140, height), : min(500, width)]  # the header's start, at twice the size
        red = (band[..., 0] > 150) & (band[..., 1] < 90) & (band[..., 2] < 90)
        rows = np.nonzero(red.any(axis=1))[0]
        assert rows.size, "no red STOP in the header's start"
        assert rows.max() - rows.min() >= 40, "STOP is not drawn at twice its size"  # ~34 px at scale 1
    finally:
        proc.terminate()
        proc.wait(15)

"""The keys window (Help ▸ Keyboard shortcuts) on a 1280×800 laptop, and at ``GDK_SCALE=2`` there — a
HiDPI screen, 640×400 logical pixels —, where it must still open inside the screen and Space still stop.

(360×720 and 800×480 in the pseudo-locale: ``test_pseudo_locale``; its search, Escape and the stop keys:
``test_keyboard_only`` and ``test_stop_keys_states``.)
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from rtmu.sim import SimConfig, SimThread

from .harness import OFFICE_MAP, Gui, idle, on_display, pump
from .process import screenshot, subscribed, wait, xdotool


def keys_window() -> str | None:
    """The X window titled "Keyboard shortcuts" while it is on screen (the screen is this test's alone;
    xdotool's ``--onlyvisible`` misses GTK 4.8's dialog, so ``xwininfo`` says whether it is mapped)."""
    found = subprocess.run(
        ["xdotool", "search", "--name", "^Keyboard shortcuts$"], capture_output=True, text=True, timeout=15
    ).stdout.split()
    for window in found:
        info = subprocess.run(["xwininfo", "-id", window], capture_output=True, text=True, timeout=15).stdout
        if "IsViewable" in info:
            return window
    return None


def test_at_gdk_scale_2_the_keys_window_opens_inside_the_screen_and_space_still_stops(
    screenshots: Path, laptop_screen: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("DISPLAY", laptop_screen)  # for xdotool and the window's process
    env = dict(os.environ, GDK_SCALE="2", XDG_CONFIG_HOME=str(tmp_path))
    with SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=1)) as sim:
        proc = subprocess.Popen(
            [sys.executable, "-m", "rtmu", "--host", "127.0.0.1", "--port", str(sim.port)],
            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
        )  # fmt: skip
        try:
            main = xdotool("search", "--sync", "--onlyvisible", "--pid", str(proc.pid), "--name", "RTMU")
            main = main.split()[0]
            wait(lambda: subscribed(sim), 30, "the window to connect")
            xdotool("windowfocus", "--sync", main)

            def f1_opened() -> bool:  # no window manager: the test gives the window the keyboard itself
                xdotool("windowfocus", "--sync", main)
                xdotool("key", "F1")
                return keys_window() is not None

            wait(f1_opened, 20, "F1 to open the keys window", poll=0.5)
            keys = keys_window()
            assert keys is not None
            geo = dict(
                line.split("=", 1)
                for line in xdotool("getwindowgeometry", "--shell", keys).split()
                if "=" in line
            )
            x, y, width, height = (int(geo[k]) for k in ("X", "Y", "WIDTH", "HEIGHT"))
            assert x >= 0 and y >= 0 and x + width <= 1280 and y + height <= 800, (x, y, width, height)
            assert width >= 2 * 300, f"{width} px: not drawn at twice the size"
            idle(1.0)
            shot = screenshot(screenshots / "test_keys_window_screens-gdk-scale-2.png", keys)
            pixels = np.asarray(Image.open(shot).convert("L")).astype(int)
            assert (pixels < 100).sum() > 2000, "the keys window is drawn (dark words on it)"
            before = sim.call(lambda: len(sim.server.stop_log))
            xdotool("windowfocus", "--sync", keys)  # (no window manager here to give it the keyboard)
            xdotool("key", "space")  # the keys window has the keyboard: Space still stops
            wait(lambda: sim.call(lambda: len(sim.server.stop_log)) > before, 10, "Space to stop the robot")
            xdotool("key", "Escape")
            wait(lambda: keys_window() is None, 10, "Escape to close the keys window")
        finally:
            proc.terminate()
            proc.wait(15)


def test_the_keys_window_on_a_1280x800_screen(screenshots: Path, laptop_screen: str) -> None:
    """(After the GDK_SCALE test: see ``laptop_screen``.)"""
    with SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=1)) as sim, on_display(laptop_screen):
        gui = Gui.start(screenshots, "keys-1280x800", "127.0.0.1", sim.port)
        try:
            gui.wait_connected()
            gui.key("F1")
            pump(
                lambda: gui.window.keys_help.shown is not None and gui.window.keys_help.shown.get_mapped(),
                5,
                "F1",
            )
            keys = gui.window.keys_help.shown
            assert keys is not None
            idle(0.3)
            x, y, w, h = gui.screen_rect(keys)
            gui.screen_shot("keys")
            assert x >= 0 and y >= 0 and x + w <= 1280 and y + h <= 800, (x, y, w, h)
            assert len(keys.shown_lines()) == len(keys.sheet.rows)
            keys.close()
        finally:
            gui.close()

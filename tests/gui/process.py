"""Helpers for GUI tests that run ``rtmu`` as a real process against a :class:`SimThread`."""

from __future__ import annotations

import os
import subprocess
import time
from collections.abc import Callable
from pathlib import Path

from PIL import ImageGrab

from patience import PATIENCE
from rtmu.sim import SimThread


def wait(condition: Callable[[], bool], timeout: float, what: str, *, poll: float = 0.02) -> None:
    """Poll ``condition`` until it holds; fail naming ``what`` after ``timeout`` seconds (× PATIENCE)."""
    deadline = time.monotonic() + timeout * PATIENCE
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout * PATIENCE:g} s waiting for {what}")
        time.sleep(poll)


def xdotool(*args: str, display: str | None = None) -> str:
    """xdotool on the tests' screen, or on ``display`` (':N') when given."""
    env = None if display is None else dict(os.environ, DISPLAY=display)
    return subprocess.run(
        ["xdotool", *args], capture_output=True, text=True, timeout=15, check=True, env=env
    ).stdout


def screenshot(path: Path, window: str | None = None, display: str | None = None) -> Path:
    """Save the X screen (or one window of it) as PNG, in-process with Pillow's XCB grab.

    Why: no external screenshot tool (ImageMagick's ``import``) to install. ``window`` is an X window
    id; the picture is the screen cropped to its geometry (xdotool), as the operator sees it.
    """
    display = display or os.environ["DISPLAY"]
    image = ImageGrab.grab(xdisplay=display)
    if window is not None:
        out = subprocess.run(
            ["xdotool", "getwindowgeometry", "--shell", window],
            capture_output=True,
            text=True,
            timeout=15,
            check=True,
            env=dict(os.environ, DISPLAY=display),
        ).stdout
        geo = dict(line.split("=", 1) for line in out.split() if "=" in line)
        x, y, w, h = (int(geo[k]) for k in ("X", "Y", "WIDTH", "HEIGHT"))
        image = image.crop((x, y, x + w, y + h))
    image.save(path)
    return path


def subscribed(sim: SimThread) -> bool:
    """True once some client has subscribed to data: the window is connected."""
    return bool(sim.call(lambda: any(session.subscriptions for session in sim.server.sessions)))


def connect_and_hold_up(proc: subprocess.Popen[str], sim: SimThread) -> str:
    """Wait for the window of ``proc`` to connect, then hold Up until the robot drives; the window id.

    A press that beats the "connected" state to the window is refused (no motion
    without a fresh press), so the key is released and pressed again, a few times.
    """
    found = xdotool("search", "--sync", "--onlyvisible", "--pid", str(proc.pid), "--name", "RTMU")
    window = found.split()[0]
    wait(lambda: subscribed(sim), 15, "the window to connect and subscribe")
    xdotool("windowfocus", "--sync", window)
    for _attempt in range(5):
        xdotool("keydown", "Up")
        try:
            wait(lambda: abs(sim.snapshot().vel) > 1.0, 2, "the robot to drive")
            return window
        except AssertionError:
            xdotool("keyup", "Up")
    raise AssertionError("the held key never drove the robot")

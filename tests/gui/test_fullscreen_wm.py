"""Full screen for real: F11 and ``rtmu --fullscreen`` under a real window manager (openbox).

The session's Xvfb has no window manager, so there a full-screen request is only
a property nobody acts on. Here each test starts its own Xvfb (1024×768) with
openbox on it, runs ``rtmu --host … --port …`` as a process against the
simulator, and reads what the X server says about the window: its geometry and
``_NET_WM_STATE``. Every wait is bounded; every process is ended afterwards.
"""

from __future__ import annotations

import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from rtmu.sim import SimConfig, SimThread

from .harness import OFFICE_MAP
from .process import screenshot, subscribed, wait
from .window_manager import managed_screen, require_openbox

SCREEN = (1024, 768)


@pytest.fixture
def wm_display() -> Iterator[dict[str, str]]:
    """A 1024×768 Xvfb with openbox running on it: the environment for X clients on that display."""
    require_openbox("test full screen")
    with managed_screen(f"{SCREEN[0]}x{SCREEN[1]}") as env:
        yield env


def _x(env: dict[str, str], *argv: str) -> str:
    """Run an X client program on the test's display; its stdout."""
    return subprocess.run(argv, env=env, capture_output=True, text=True, timeout=15, check=True).stdout


def _rtmu_command() -> list[str]:
    script = Path(sys.executable).parent / "rtmu"
    return [str(script)] if script.exists() else [sys.executable, "-m", "rtmu"]


def _geometry(env: dict[str, str], window: str) -> tuple[int, int, int, int]:
    """(x, y, width, height) of the window as the X server has it now."""
    values = dict(
        line.split("=", 1) for line in _x(env, "xdotool", "getwindowgeometry", "--shell", window).split()
    )
    return int(values["X"]), int(values["Y"]), int(values["WIDTH"]), int(values["HEIGHT"])


def _is_fullscreen(env: dict[str, str], window: str) -> bool:
    return "_NET_WM_STATE_FULLSCREEN" in _x(env, "xprop", "-id", window, "_NET_WM_STATE")


def _fills_screen(env: dict[str, str], window: str) -> bool:
    return _is_fullscreen(env, window) and _geometry(env, window) == (0, 0, *SCREEN)


def _shot(env: dict[str, str], path: Path) -> None:
    screenshot(path, display=env["DISPLAY"])
    assert path.stat().st_size > 0


class Rtmu:
    """``rtmu`` as a process on the test's display, connected to the simulator; its top-level window id."""

    def __init__(self, env: dict[str, str], port: int, config: Path, *extra: str) -> None:
        self.env = dict(env, XDG_CONFIG_HOME=str(config))
        self.proc = subprocess.Popen(
            [*_rtmu_command(), "--host", "127.0.0.1", "--port", str(port), *extra],
            env=self.env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        found = _x(
            self.env,
            "xdotool",
            "search",
            "--sync",
            "--onlyvisible",
            "--pid",
            str(self.proc.pid),
            "--name",
            "RTMU",
        )
        self.window = found.split()[0]

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)  # the window's own safe quit
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait(5)


def test_f11_makes_the_window_fill_the_screen_and_back(
    wm_display: dict[str, str], tmp_path: Path, screenshots: Path
) -> None:
    env = wm_display
    with SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=1)) as sim:
        app = Rtmu(env, sim.port, tmp_path)
        try:
            wait(lambda: subscribed(sim), 15, "the window to connect and subscribe")
            window = app.window
            normal = _geometry(env, window)
            assert not _is_fullscreen(env, window)
            assert normal[2:] != SCREEN, f"the window already fills the screen: {normal}"
            _x(env, "xdotool", "windowactivate", "--sync", window)
            _x(env, "xdotool", "key", "F11")  # a real key press to the focused window, not a sent event
            wait(lambda: _fills_screen(env, window), 10, "F11 to make the window full screen")
            _shot(env, screenshots / "test_fullscreen_wm-01-f11-fullscreen.png")
            _x(env, "xdotool", "windowactivate", "--sync", window)
            _x(env, "xdotool", "key", "F11")
            wait(lambda: not _is_fullscreen(env, window), 10, "F11 again to leave full screen")
            wait(lambda: _geometry(env, window)[2:] == normal[2:], 10, "the window's normal size again")
            _shot(env, screenshots / "test_fullscreen_wm-02-f11-normal.png")
            assert app.proc.poll() is None, "rtmu exited"
        finally:
            app.close()
        assert app.proc.returncode == 0


def test_the_fullscreen_option_starts_full_screen(
    wm_display: dict[str, str], tmp_path: Path, screenshots: Path
) -> None:
    env = wm_display
    with SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=1)) as sim:
        app = Rtmu(env, sim.port, tmp_path, "--fullscreen")
        try:
            wait(lambda: _fills_screen(env, app.window), 10, "--fullscreen to open the window full screen")
            wait(lambda: subscribed(sim), 15, "the window to connect and subscribe")
            _shot(env, screenshots / "test_fullscreen_wm-03-option-fullscreen.png")
            assert app.proc.poll() is None, "rtmu exited"
        finally:
            app.close()
        assert app.proc.returncode == 0

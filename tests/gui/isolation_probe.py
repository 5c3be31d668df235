"""Two GUI tests for ``tests/test_gui_isolation.py`` only: the first fails on purpose while driving.

The file name does not match ``test_*.py``, so a normal run never collects it; the isolation test
runs it in a pytest of its own. The first test starts a simulator and the real ``rtmu`` window as
processes, holds Up until the robot drives and then fails — with no ``try``/``finally`` of its own,
as a test that breaks unexpectedly would. The GUI conftest must release the key, end both processes
and the window's guardian, so that the second test starts on a clean X server.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

from patience import cli_timeout

from .harness import Gui, pump
from .process import xdotool

if os.environ.get("RTMU_ISOLATION_PROBE") != "1":  # pragma: no cover - only the isolation test runs it
    pytest.skip("run by tests/test_gui_isolation.py", allow_module_level=True)


def _vel(port: int) -> float:
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "rtmu",
            "status",
            f"127.0.0.1:{port}",
            "--once",
            "--json",
            "--timeout",
            cli_timeout(5),
        ],
        capture_output=True,
        text=True,
        timeout=20,
        check=True,
    ).stdout
    return float(json.loads(out)["vel"])


def _start_sim() -> tuple[subprocess.Popen[str], int]:
    sim = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "sim", "--port", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    assert sim.stdout is not None
    match = re.search(r"listening on 127\.0\.0\.1:(\d+)", sim.stdout.readline())
    assert match, "the simulator did not say its port"
    return sim, int(match.group(1))


def test_1_fails_while_driving(tmp_path: Path) -> None:
    _sim, port = _start_sim()
    window = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "--host", "127.0.0.1", "--port", str(port)],
        env=dict(os.environ, XDG_CONFIG_HOME=str(tmp_path)),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    found = xdotool("search", "--sync", "--onlyvisible", "--pid", str(window.pid), "--name", "RTMU")
    xid = found.split()[0]
    deadline = time.monotonic() + 30
    while True:  # a press that beats "connected" is refused: press again until the robot drives
        xdotool("windowfocus", "--sync", xid)
        xdotool("keydown", "Up")
        time.sleep(1.0)
        if abs(_vel(port)) > 1.0:
            break
        xdotool("keyup", "Up")
        assert time.monotonic() < deadline, "the window never drove the robot"
    Path(os.environ["RTMU_ISOLATION_PIDS"]).write_text(f"{_sim.pid} {window.pid}\n")
    raise AssertionError("failing on purpose while Up is held and the robot drives")


def test_2_drives_and_passes(screenshots: Path) -> None:
    _sim, port = _start_sim()
    try:
        # Nothing of the first test is on the display, and the robot is at rest before any press.
        leftover = subprocess.run(
            ["xdotool", "search", "--onlyvisible", "--name", "RTMU"], capture_output=True
        )
        assert leftover.stdout == b"", "a window of the failed test is still on the display"
        gui = Gui.start(screenshots, "isolation-probe", "127.0.0.1", port)
        try:
            gui.shot("connected")
            assert _vel(port) == 0.0
            gui.keydown("Up")
            pump(lambda: gui.model.robot.value.vel > 1.0, 10, "the robot to drive")
            gui.keyup("Up")
            pump(lambda: gui.model.robot.value.vel == 0.0, 10, "the robot to stop")
        finally:
            gui.close()
    finally:
        _sim.terminate()
        _sim.wait(10)


def test_3_passes_but_leaks_a_process() -> None:
    """Run alone by the isolation test: the conftest must end the process and fail this test."""
    subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"])


def test_4_passes_but_leaves_a_dialog_on_screen() -> None:
    """Run alone by the isolation test: a dialog left mapped would take the next test's clicks; the
    conftest must destroy it and fail this test."""
    from gi.repository import Gtk

    left = Gtk.Window(title="Left on screen")
    left.present()
    pump(left.get_mapped, 5, "the dialog on screen")


def test_5_fails_with_the_menu_open(screenshots: Path) -> None:
    """Run with test_6 by the isolation test: fails while the main menu (a popover, with its grab) is open."""
    sim, port = _start_sim()
    try:
        gui = Gui.start(screenshots, "isolation-menu-open", "127.0.0.1", port)
        gui.focus()
        gui.window.actions.activate("win.open-menu")
        pump(lambda: gui.window.menu_button.get_popover().get_visible(), 5, "the menu")
        gui.shot("menu-open")
        raise AssertionError("failing on purpose with the menu open")
    finally:
        sim.terminate()
        sim.wait(10)


def test_6_keys_reach_the_next_window(screenshots: Path) -> None:
    sim, port = _start_sim()
    try:
        gui = Gui.start(screenshots, "isolation-keys-after", "127.0.0.1", port)
        try:
            gui.wait_connected()
            gui.focus()
            before = gui.operator.speed.value.percent
            gui.key("plus")
            pump(lambda: gui.operator.speed.value.percent == before + 10, 5, "the speed key")
            gui.shot("keys-reach")
        finally:
            gui.close()
    finally:
        sim.terminate()
        sim.wait(10)

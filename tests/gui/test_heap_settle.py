"""The window settles its heap only while no drive is held.

Settling (``base.heap.settle``, a few seconds after the window shows) is one full collection over
everything the start-up built, on the UI thread. On CI's loaded machine it once outlasted the drive
lease while Up was held ("the drive was not renewed for 0.34 s"): the robot stopped under the
operator's finger. Here Up is held when the settling comes due; it waits, and happens once the key
is released. The window's own timer is put off for the test, which calls its callback at the moment
it chooses, as the timer would.
"""

from __future__ import annotations

from pathlib import Path

import gi
import pytest

from rtmu.sim import SimConfig, SimThread
from rtmu.ui import application

from .harness import OFFICE_MAP, Gui, idle, pump

gi.require_version("GLib", "2.0")
from gi.repository import GLib  # noqa: E402


def test_the_heap_settles_once_the_held_drive_is_released(
    screenshots: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    held_when_settled: list[bool] = []
    real_settle = application.settle
    monkeypatch.setattr(application, "SETTLE_AFTER_MS", 10 * 60 * 1000)  # the test says when
    with SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=1)) as sim:
        gui = Gui.start(screenshots, "heap-settle", "127.0.0.1", sim.port)
        controller = gui.window.controller
        # Only this window's settling counts: an earlier test's window, closed in this process, may
        # still have its timer due (it settles the process's heap, not this window's).
        real_step = gui.app._settle_heap
        ours = [False]

        def step() -> bool:
            ours[0] = True
            try:
                return real_step()
            finally:
                ours[0] = False

        def settle() -> int:
            if ours[0]:
                held_when_settled.append(controller.needs_tick)
            return real_settle()

        monkeypatch.setattr(gui.app, "_settle_heap", step)  # its retries look the method up again
        monkeypatch.setattr(application, "settle", settle)
        try:
            gui.keydown("Up")
            try:
                pump(lambda: abs(sim.snapshot().vel) > 1.0, 8, "the held Up to drive")
                assert gui.app._settle_heap() is False  # the moment it comes due: with Up held
                idle(2.5)  # it looks again every second
                assert held_when_settled == [], "settled while a drive was held"
                assert controller.needs_tick and abs(sim.snapshot().vel) > 1.0, "still driving"
                gui.shot("driving-with-the-heap-unsettled")
            finally:
                gui.keyup("Up")
            pump(lambda: held_when_settled != [], 5, "the heap to settle once Up is released")
            assert held_when_settled == [False]
        finally:
            gui.close()


def test_a_closed_window_leaves_no_settling_behind(
    screenshots: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A window closed before its settling came due cancels it: another window of the same process
    (tests open many) must not have a full collection run under its held drive by one long gone."""
    monkeypatch.setattr(application, "SETTLE_AFTER_MS", 10 * 60 * 1000)
    with SimThread(SimConfig(port=0, map_path=OFFICE_MAP, seed=1)) as sim:
        gui = Gui.start(screenshots, "heap-settle-closed", "127.0.0.1", sim.port)
        gui.shot("before-closing")
        due = gui.app._settle_source
        assert due and GLib.MainContext.default().find_source_by_id(due) is not None, "settling is due"
        gui.close()
        assert GLib.MainContext.default().find_source_by_id(due) is None, (
            "a closed window's settling stays due"
        )

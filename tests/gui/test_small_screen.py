"""On an 800×480 screen (a second Xvfb): the menu and the keys window fit, the window goes narrower.

What is measured is the X windows themselves (``xwininfo``: popovers and the
keys window are surfaces of their own), and GTK's own complaints: a
layout that does not fit makes GTK print warnings, which fail the test.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest

from simulators import running

from .harness import OFFICE_MAP, Gui, on_display, pump

W, H = 800, 480
_HARMLESS = ("Unable to acquire session bus",)


@pytest.fixture
def small(screenshots: Path, small_screen: str, request: pytest.FixtureRequest) -> Iterator[Gui]:
    with (
        running(map_path=OFFICE_MAP, camera=True, seed=1) as sim,
        on_display(small_screen),
    ):
        gui = Gui.start(screenshots, request.node.name, "127.0.0.1", sim.port)
        try:
            yield gui
        finally:
            gui.close()


def gtk_complaints(text: str) -> list[str]:
    lines = [ln for ln in text.splitlines() if re.search(r"-(WARNING|CRITICAL) \*\*", ln)]
    return [ln for ln in lines if not any(h in ln for h in _HARMLESS)]


def inside_screen(rect: tuple[int, int, int, int]) -> bool:
    x, y, w, h = rect
    return x >= 0 and y >= 0 and x + w <= W and y + h <= H


def test_menu_and_keys_window_fit_an_800x480_screen(small: Gui, capfd: pytest.CaptureFixture[str]) -> None:
    gui = small
    window = gui.window
    assert inside_screen(gui.screen_rect(window)), gui.screen_rect(window)
    gui.shot("800x480")
    gui.click(window.menu_button)
    popover = window.menu_button.get_popover()
    pump(lambda: popover is not None and popover.get_mapped(), 3, "the menu")
    rect = gui.screen_rect(popover)
    gui.screen_shot("menu")
    assert inside_screen(rect), f"the menu at {rect} leaves the 800×480 screen"
    popover.popdown()
    pump(lambda: not popover.get_mapped(), 3, "the menu to close")
    # F1 itself is tested on the big screen; here the menu's keyboard grab may still be ending.
    window.activate_action("win.show-keys", None)
    keys = window.keys_help.shown
    assert keys is not None
    pump(keys.get_mapped, 5, "the keys window")
    rect = gui.screen_rect(keys)
    gui.screen_shot("keys")
    assert inside_screen(rect), f"the keys window at {rect} leaves the 800×480 screen"
    keys.close()
    assert not gtk_complaints(capfd.readouterr().err)


def test_the_window_goes_narrower_and_gives_up_minor_columns_first(
    small: Gui, capfd: pytest.CaptureFixture[str]
) -> None:
    gui = small
    window = gui.window
    toolbar = window.toolbar
    pump(lambda: not toolbar.hidden_columns(), 3, "every column at 800 px")
    window.set_default_size(560, 400)
    pump(lambda: window.get_width() <= 560, 5, "the window to shrink to 560 px")
    pump(lambda: "rot" in toolbar.hidden_columns(), 3, "minor columns to give way")
    hidden = toolbar.hidden_columns()
    assert {"battery", "mode", "link"}.isdisjoint(hidden), hidden
    assert toolbar.row.measure(0, -1)[0] <= toolbar.get_width(), "what is shown fits"
    assert window.stop_button.get_mapped(), "STOP stays on screen"
    gui.shot("560x400")
    window.set_default_size(W, H)
    pump(lambda: window.get_width() > 700, 5, "the window to grow back")
    pump(lambda: not toolbar.hidden_columns(), 3, "every column back at 800 px")
    gui.shot("back-to-800")
    assert not gtk_complaints(capfd.readouterr().err)

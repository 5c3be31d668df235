"""The steps the "why won't it move?" window tests share: put the simulator in a state, hold a drive key
for the hint, open the why window, go through a fix's confirmation, and check STOP still stops.

Real X input throughout (xdotool under the harness's Xvfb), the simulator checked at its own end.
"""

from __future__ import annotations

from patience import cli_timeout
from rtmu.base import exit_codes as codes
from rtmu.cli import main
from rtmu.sim import SimThread
from rtmu.ui.why_window import WhyWindow

from .harness import Gui, pump
from .stop_paths import MenuEntry, owned_windows

WHY_ROW = MenuEntry((), "Why won't it move?…", "win.why")


def command(sim: SimThread, name: str, *args: str) -> None:
    """One of the simulator's own simple commands, sent as an operator would (``rtmu run``)."""
    assert main(["run", f"127.0.0.1:{sim.port}", name, *args, "--timeout", cli_timeout(5)]) == codes.EXIT_OK


def stops(sim: SimThread) -> int:
    """How many ``stop`` requests the simulator has heard."""
    return sim.call(lambda: len(sim.server.stop_log))  # type: ignore[union-attr]


def xid(window: object) -> int:
    from gi.repository import GdkX11

    return GdkX11.X11Surface.get_xid(window.get_surface())  # type: ignore[attr-defined]


def why_window(gui: Gui) -> WhyWindow:
    """The why window once it shows the robot's answer, moved off the header bar (no window manager
    places it) so STOP stays in reach."""
    pump(lambda: any(isinstance(w, WhyWindow) for w in owned_windows(gui.window)), 5, "the why window")
    found = next(w for w in owned_windows(gui.window) if isinstance(w, WhyWindow))
    gui.xdotool("windowmove", "--sync", str(xid(found)), "420", "300")
    pump(lambda: found.answer is not None and not found.asking, 15, "the robot's answer")
    return found


def ask_why(gui: Gui) -> WhyWindow:
    """``?`` in the main window, as an operator types it."""
    gui.focus()
    gui.key("question")
    return why_window(gui)


def hint(gui: Gui) -> str:
    return gui.window.banners.text("why") or ""


def space_stops(gui: Gui, sim: SimThread, what: str) -> None:
    before = stops(sim)
    gui.key("space")
    pump(lambda: stops(sim) > before, 5, f"Space to stop the robot {what}")


def stop_button_stops(gui: Gui, sim: SimThread, what: str) -> None:
    before = stops(sim)
    gui.click(gui.window.stop_button)
    pump(lambda: stops(sim) > before, 5, f"the STOP button to stop the robot {what}")


def hold_up_for_the_hint(gui: Gui) -> None:
    """Hold the Up key until the hint of a held drive that does not move shows, then let go."""
    gui.focus()
    gui.keydown("Up")
    try:
        pump(lambda: bool(hint(gui)), 15, "the hint of a held drive that does not move")
        gui.shot("hint")
    finally:
        gui.keyup("Up")


def click_in(gui: Gui, widget: object) -> None:
    """A real click on a dialog's widget, the pointer moved onto its window first (as test_config_page)."""
    from .test_config_page import click

    click(gui, widget)


def offer_the_fix(gui: Gui, why: WhyWindow, label: str) -> None:
    """Click the why window's fix button (it must read ``label``) and wait for its confirmation."""
    assert why.fix_button.get_visible() and why.fix_button.get_label() == label, why.fix_button.get_label()
    gui.xdotool("windowfocus", "--sync", str(xid(why)))
    click_in(gui, why.fix_button)
    pump(lambda: why.confirm.asking, 5, "the confirmation")


def say_yes(gui: Gui, why: WhyWindow) -> None:
    """The confirmation's yes, clicked (asked again first if something took it away meanwhile)."""
    gui.xdotool("windowfocus", "--sync", str(xid(why)))
    if not why.confirm.asking:
        click_in(gui, why.fix_button)
    pump(lambda: why.confirm.asking, 5, "the confirmation again")
    click_in(gui, why.confirm.yes_button)


def free_again(why: WhyWindow) -> None:
    """Wait for the why window's new answer to say the robot can move."""
    pump(lambda: not why.asking and why.answer is not None and why.answer.can_move, 15, "the new answer")

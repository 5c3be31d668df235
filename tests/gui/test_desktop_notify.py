"""Desktop notifications from the real window while it is not focused, heard by the desktop's side.

The real window on the real simulator; ``fake_desktop`` is the notification server on the test's
session bus (Xvfb has none). What is checked: a server popup and a battery falling to low are sent
as notifications only while another window has the focus, the popup's title marked as the robot's
words; a kind switched off in View ▸ Desktop notifications (and so in the settings) is not sent;
focusing the window again withdraws what was sent.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from rtmu.sim import SimThread
from simulators import simulator

from .desktop_side import Desktop, fake_desktop
from .harness import OFFICE_MAP, Gui, idle, pump


@pytest.fixture
def desktop() -> Iterator[Desktop]:
    with fake_desktop() as d:
        yield d


sim = simulator(map_path=OFFICE_MAP, camera=False, seed=1)


def popup(sim: SimThread, title: str) -> None:
    world = sim.server.world  # type: ignore[union-attr]
    sim.call(lambda: world.create_popup(title, "Please answer"))


def test_popups_and_a_low_battery_reach_the_desktop_only_while_the_window_is_away(
    desktop: Desktop, gui: Gui, sim: SimThread
) -> None:
    from gi.repository import Gtk

    gui.wait_connected()
    gui.focus()
    popup(sim, "Focused: no notification")
    pump(lambda: len(gui.window.model.popups.value.open) == 1, 10, "the first popup card")
    idle(0.5)
    assert desktop.of("Notify") == [], "a notification while the window had the focus"

    other = Gtk.Window(title="another application")
    other.present()
    pump(lambda: not gui.window.is_active(), 10, "the window to lose the focus")
    gui.window.activate_action("win.notify-popup", None)  # View ▸ Desktop notifications ▸ off
    assert gui.window.desktop.notifier.choices["popup"] is False
    popup(sim, "Switched off")
    pump(lambda: len(gui.window.model.popups.value.open) == 2, 10, "the second popup card")
    idle(0.5)
    assert desktop.of("Notify") == [], "a notification the operator switched off"

    gui.window.activate_action("win.notify-popup", None)  # on again
    popup(sim, "Lift <b>blocked</b>")
    pump(lambda: len(desktop.of("Notify")) == 1, 10, "the popup's notification")
    (note,) = desktop.of("Notify")
    assert "a message waits" in note["summary"]
    assert note["body"] == "The robot says: “Lift <b>blocked</b>”"

    body = sim.server.world.body  # type: ignore[union-attr]
    sim.call(lambda: setattr(body, "battery_v", 11.3))  # under the P3-DX's low level
    # (the simulator, as a real server may, also raises a "Low battery" popup: one more popup note)
    low = lambda: [n for n in desktop.of("Notify") if "battery low" in n["summary"]]  # noqa: E731
    pump(lambda: bool(low()), 15, "the low battery's notification")
    assert low()[0]["urgency"] == 1 and "V" in low()[0]["body"], low()

    gui.shot("away-with-popups")
    other.close()
    gui.focus()
    pump(lambda: gui.window.is_active(), 10, "the window to have the focus again")
    pump(lambda: len(desktop.of("CloseNotification")) == 2, 10, "both kinds withdrawn (popup, battery)")

"""Focus returning to the window: a key held through the focus loss drives again only after a real release."""

from __future__ import annotations

import gi

from simulators import simulator

from .harness import OFFICE_MAP, Gui, pump

gi.require_version("Gtk", "4.0")
gi.require_version("GdkX11", "4.0")
from gi.repository import GdkX11, Gtk  # noqa: E402

sim = simulator(map_path=OFFICE_MAP, seed=1)


def test_a_release_after_focus_returns_is_real_and_the_next_press_drives(gui: Gui) -> None:
    controller = gui.window.controller
    lease = controller.link.lease
    other = Gtk.Window(title="elsewhere")
    other.present()
    try:
        pump(other.get_mapped, 3, "the other window")
        gui.focus()
        controller.press("forward")  # as a held Up key would
        assert lease.view().live
        gui.xdotool("windowfocus", "--sync", str(GdkX11.X11Surface.get_xid(other.get_surface())))
        pump(lambda: not gui.window.is_active(), 3, "the RTMU window to lose focus")
        assert not lease.view().live, "focus loss stops"
        gui.focus()
        # No auto-repeat press came after focus returned: the window knows it has the keys again.
        controller.release("forward")
        controller.press("forward")
        assert lease.view().live, "a fresh press after a real release must drive"
        gui.shot("driving-after-refocus")
        controller.release("forward")
    finally:
        other.destroy()

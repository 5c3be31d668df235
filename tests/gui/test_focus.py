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


def test_a_focus_left_on_a_page_switched_away_is_put_back_by_the_event_not_the_backstop(gui: Gui) -> None:
    """A stack page switched away unmaps its widgets without moving the window's focus (GTK keeps it
    there: keys would go nowhere). ``key_reach`` hears the focus widget's ``unmap`` and puts it back
    before the next event: here within a few non-blocking main-loop turns, far sooner than its 1 s
    backstop could run."""
    from gi.repository import GLib

    window = gui.window
    gui.focus()
    stack = Gtk.Stack(halign=Gtk.Align.START, valign=Gtk.Align.START)
    button = Gtk.Button(label="focus me")
    stack.add_named(button, "one")
    stack.add_named(Gtk.Label(label="the other page"), "two")
    window.map_page.add_overlay(stack)
    try:
        pump(button.get_mapped, 3, "the test button on screen")
        button.grab_focus()
        pump(lambda: window.get_focus() is button, 3, "the button to take the focus")
        before = window.key_reach.repairs
        stack.set_visible_child_name("two")  # unmaps the button; GTK leaves the focus on it
        context = GLib.MainContext.default()
        for _ in range(50):  # non-blocking turns: milliseconds, never the backstop's second
            context.iteration(False)
        focus = window.get_focus()
        assert window.key_reach.repairs == before + 1, "the stranded focus was not put back by the event"
        assert focus is None or focus.get_mapped()
        gui.key("space")  # and the stop key is heard by the window again
        gui.shot("focus-put-back-after-a-page-switch")
    finally:
        window.map_page.remove_overlay(stack)

"""Which toplevels are a window's own: its dialogs, and theirs (the ``transient-for`` chain).

One rule for the places that ask: the stop keys (every surface of the window carries them), the
keys' reach (a dialog of ours has the keyboard), and the window's shutdown, which pops down its
popovers and destroys its dialogs itself — GTK 4 destroys a ``destroy-with-parent`` dialog only
when its parent is disposed, and a reference held elsewhere (a test, a callback) delays that,
leaving dialogs on screen.
"""

from __future__ import annotations

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

MAX_CHAIN = 32
"""A transient-for chain longer than this is taken as a cycle, not followed further."""


def belongs_to(window: Gtk.Window, other: Gtk.Window | None) -> bool:
    """``other`` is ``window`` itself or one of its dialogs, at any depth."""
    seen = 0
    while other is not None and seen < MAX_CHAIN:
        if other is window:
            return True
        other = other.get_transient_for()
        seen += 1
    return False


def dialogs_of(window: Gtk.Window) -> list[Gtk.Window]:
    """Every toplevel of this process, other than ``window``, whose chain leads to ``window``."""
    return [
        top
        for top in Gtk.Window.list_toplevels()
        if isinstance(top, Gtk.Window) and top is not window and belongs_to(window, top)
    ]


def close_popovers(window: Gtk.Window) -> int:
    """Pop down every popover open in ``window`` (how many were): GTK 4.8 keeps an open popover's
    pointer and keyboard grab on X11 after its window is destroyed, and the X server would then send
    every later key and click of the session to a surface that is gone."""
    closed = 0
    stack: list[Gtk.Widget] = [window]
    while stack:
        widget = stack.pop()
        if isinstance(widget, Gtk.Popover) and widget.get_visible():
            widget.popdown()
            closed += 1
        child = widget.get_first_child()
        while child is not None:
            stack.append(child)
            child = child.get_next_sibling()
    return closed

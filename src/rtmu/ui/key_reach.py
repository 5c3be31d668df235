"""The window never loses its keys silently: stranded focus is put back, and lost keys are said.

Two ways keys went missing:

* **Focus stranded in a closed popover.** GTK 4.8's ``GtkPopoverMenu``, closed by a pick in one of
  its submenus (View, Server), switches back to its main page *after* it has hidden and gives that
  page's scrolled window the window's focus. The window then keeps a focus widget that is not mapped,
  and GTK delivers every key to it: no controller — not even the window's capture-phase key router —
  sees Space, Up or Escape until the menu is opened and closed again. :class:`KeyReach` watches the
  window's focus and, as soon as it lands on a widget that is not on screen — or the widget holding
  it leaves the screen (its ``unmap``: a page switched away, a popover closed) — moves it back (to
  the popover's button when it can take it, else to the window itself) before the next event is
  handled. Those two events are the only ways a focus can be stranded, so nothing polls for it; a
  once-a-second check stays as a backstop (at 10 Hz it was the idle window's most frequent wake-up).
* **The keyboard is elsewhere** (another program, one of the window's dialogs): the drive keys
  cannot reach the window. The controller already ends held drives and refuses D-pad drives then;
  here a banner (topic ``keys``, kept while it lasts) says so ("Keys inactive — click the map", or
  which dialog has them and that Space still stops there), from ``control.key_rules.keys_note``.
"""

from __future__ import annotations

from typing import Any

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import GLib, Gtk  # noqa: E402

from ..base.i18n import _  # noqa: E402
from ..control.key_rules import keys_note  # noqa: E402
from ..model.observables import Phase  # noqa: E402
from .dialog_chain import dialogs_of  # noqa: E402

MainWindow = Any
"""``ui.window.MainWindow`` (which imports this module): named, not imported."""

CHECK_MS = 1000
"""The backstop: a stranded focus or a stale note is caught by events first (see the module notes)."""
SETTLE_MS = 200
"""After the window's activity changes, the note is made again once this later: the dialog that took
the keyboard is not always active yet when the window hears it lost it."""
TOPIC = "keys"


def stranded(window: Gtk.Window) -> Gtk.Widget | None:
    """The window's focus widget when it is not on screen (keys sent to it are lost), else None."""
    focus = window.get_focus()
    if focus is None or focus.get_mapped():
        return None
    return focus


def _popover_of(widget: Gtk.Widget | None) -> Gtk.Popover | None:
    while widget is not None and not isinstance(widget, Gtk.Popover):
        widget = widget.get_parent()
    return widget


class KeyReach:
    """See the module notes. ``repairs`` counts the stranded focuses put back (tests read it)."""

    def __init__(self, window: MainWindow) -> None:
        self.window = window
        self.repairs = 0
        self.text = ""
        """What the window says about its keys now ("" while they reach it)."""
        self._handlers = [
            window.connect("notify::focus-widget", lambda *_a: self._focus_moved()),
            window.connect("notify::is-active", lambda *_a: self._activity_changed()),
        ]
        self._watched: tuple[Gtk.Widget, int] | None = None
        """The focus widget and its ``unmap`` handler."""
        self._timer = GLib.timeout_add(CHECK_MS, self._check)
        self._settle = 0
        self._unwatch_connection = window.model.connection.observe(lambda *_a: self.refresh())
        self.refresh()
        self._watch(window.get_focus())

    def close(self) -> None:
        for source in (self._timer, self._settle):
            if source:
                GLib.source_remove(source)
        self._timer = self._settle = 0
        self._watch(None)
        self._unwatch_connection()
        for handler in self._handlers:
            self.window.disconnect(handler)
        self._handlers = []

    # -- stranded focus ----------------------------------------------------------------------
    def _focus_moved(self) -> None:
        self._watch(self.window.get_focus())
        if stranded(self.window) is not None:
            self._repair_soon()

    def _watch(self, focus: Gtk.Widget | None) -> None:
        """Hear when ``focus`` (the window's focus widget) leaves the screen."""
        if self._watched is not None:
            widget, handler = self._watched
            if widget is focus:
                return
            widget.disconnect(handler)
            self._watched = None
        if focus is not None:
            self._watched = (focus, focus.connect("unmap", lambda *_a: self._repair_soon()))

    def _repair_soon(self) -> None:
        """Repair once the current emission is over (an ``unmap`` handler runs before the widget is
        marked unmapped), before the next input event."""
        GLib.idle_add(self._repair_once, priority=GLib.PRIORITY_HIGH)  # type: ignore[call-arg]

    def _repair_once(self) -> bool:
        self.repair()
        return False

    def repair(self) -> bool:
        """Put a stranded focus back where keys reach the window; True when there was one."""
        focus = stranded(self.window)
        if focus is None:
            return False
        popover = _popover_of(focus)
        button = popover.get_parent() if popover is not None else None
        self.window.set_focus(None)
        if button is not None and button.get_mapped() and button.get_focusable():
            button.grab_focus()
        self.repairs += 1
        return True

    def _check(self) -> bool:
        self.repair()
        self.refresh()
        return True

    def _activity_changed(self) -> None:
        self.refresh()
        if self._settle:
            GLib.source_remove(self._settle)
        self._settle = GLib.timeout_add(SETTLE_MS, self._settled)

    def _settled(self) -> bool:
        self._settle = 0
        self.refresh()
        return False

    # -- the note ------------------------------------------------------------------------------
    def refresh(self) -> None:
        window = self.window
        connected = window.model.connection.value.phase is Phase.CONNECTED
        active = window.is_active()
        dialog = self._dialog_title() if connected and not active else ""
        text = keys_note(window_active=active, connected=connected, dialog=dialog)
        if connected and not active:  # a dialog of this window carries the stop keys: Space reaches it
            window.controller.keys_reach = bool(dialog)
        shown = window.banners.text(TOPIC)
        if text and shown != text:
            window.banners.tell(TOPIC, "warning", text, timeout=None)  # back if closed while it lasts
        elif not text and shown is not None:
            window.banners.dismiss(TOPIC)
        self.text = text

    def _dialog_title(self) -> str:
        """The title of one of this window's own windows that has the keyboard now ("" if none)."""
        for other in dialogs_of(self.window):
            if other.is_active():
                return other.get_title() or _("a dialog")
        return ""

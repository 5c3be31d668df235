"""The configuration page's "discard your unsaved edits?" question, inline, never a second dialog.

Escape or the title bar's close with unsaved edits shows this bar instead of closing: "Keep editing"
(the focus, and Escape) hides it, "Discard and close" closes. A bar inside the page, rather than a
modal dialog, keeps the page's own keys (and the stop keys the page carries) where they are.
"""

from __future__ import annotations

from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

from ..base.i18n import _  # noqa: E402


class DiscardQuestion(Gtk.Box):
    """Asks before unsaved edits are lost; ``discard()`` is called only on "Discard and close"."""

    def __init__(self, discard: Callable[[], None]) -> None:
        super().__init__(spacing=8, visible=False)
        self.add_css_class("config-banner")
        self.label = Gtk.Label(xalign=0.0, wrap=True, hexpand=True)
        self.keep_button = Gtk.Button(label=_("Keep editing"))
        self.keep_button.connect("clicked", lambda _b: self.dismiss())
        self.discard_button = Gtk.Button(label=_("Discard and close"))
        self.discard_button.add_css_class("destructive-action")
        self.discard_button.connect("clicked", lambda _b: discard())
        for child in (self.label, self.keep_button, self.discard_button):
            self.append(child)

    @property
    def asking(self) -> bool:
        return self.get_visible()

    def ask(self, unsaved: int) -> None:
        edits = _("1 unsaved edit") if unsaved == 1 else _("{unsaved} unsaved edits").format(unsaved=unsaved)
        self.label.set_text(_("Close and lose {edits}? Save keeps them.").format(edits=edits))
        self.set_visible(True)
        self.keep_button.grab_focus()

    def dismiss(self) -> None:
        self.set_visible(False)

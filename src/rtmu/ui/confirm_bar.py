"""A confirmation in place: what will be sent, in words, with Cancel (focused) and one button that sends.

The why window's fixes and the console's calls that change something never go on one click: the
button that would send them shows this bar instead, and only its yes button sends. Cancel has the
keyboard first, so a Return typed by habit sends nothing; Esc in the bar cancels too. Being a row of
its own window, it keeps Space for STOP (``stop_keys`` guards every surface).
"""

from __future__ import annotations

from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gdk, Gtk, Pango  # noqa: E402

from ..base.i18n import _  # noqa: E402


class ConfirmBar(Gtk.Revealer):
    """Hidden until :meth:`ask`; ``yes`` runs only from its own button."""

    def __init__(self) -> None:
        super().__init__(transition_type=Gtk.RevealerTransitionType.NONE, reveal_child=False)
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=6)
        box.add_css_class("card")
        for side in ("start", "end", "top", "bottom"):
            getattr(box, f"set_margin_{side}")(6)
        self.question = Gtk.Label(wrap=True, xalign=0.0, selectable=False)
        self.question.set_max_width_chars(60)
        self.question.set_wrap_mode(Pango.WrapMode.WORD_CHAR)  # a word longer than the line breaks too
        buttons = Gtk.Box(spacing=6, halign=Gtk.Align.END)
        self.cancel_button = Gtk.Button(label=_("Cancel"))
        self.yes_button = Gtk.Button(label=_("Send it"))
        self.yes_button.add_css_class("destructive-action")
        self.cancel_button.connect("clicked", lambda _b: self.cancel())
        self.yes_button.connect("clicked", lambda _b: self._yes())
        buttons.append(self.cancel_button)
        buttons.append(self.yes_button)
        box.append(self.question)
        box.append(buttons)
        keys = Gtk.EventControllerKey()
        keys.connect("key-pressed", self._key)
        box.add_controller(keys)
        self.set_child(box)
        self._pending: Callable[[], None] | None = None

    @property
    def asking(self) -> bool:
        return self._pending is not None

    def ask(self, question: str, yes_label: str, yes: Callable[[], None]) -> None:
        """Show ``question`` (plain text, never markup); ``yes`` runs only if its button is pressed."""
        self._pending = yes
        self.question.set_text(question)
        self.yes_button.set_label(yes_label)
        self.set_reveal_child(True)
        self.cancel_button.grab_focus()

    def cancel(self) -> None:
        self._pending = None
        self.set_reveal_child(False)

    def _yes(self) -> None:
        pending, self._pending = self._pending, None
        self.set_reveal_child(False)
        if pending is not None:
            pending()

    def _key(self, _c: Gtk.EventControllerKey, keyval: int, _code: int, _state: Gdk.ModifierType) -> bool:
        if keyval == Gdk.KEY_Escape and self.asking:
            self.cancel()
            return True
        return False

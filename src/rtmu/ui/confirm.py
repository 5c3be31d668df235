"""A small confirmation window that names what it is about: Cancel, or the one action it asks for.

GTK 4.8 has no ``Gtk.AlertDialog``; this is a plain transient window, so ``stop_keys`` gives it Space
like every other surface of the window. The action button is the only way to go on: Escape and the
window's close button cancel. Text is plain (names come from the robot or the disk, never markup).
"""

from __future__ import annotations

from collections.abc import Callable

import gi

gi.require_version("Gdk", "4.0")
gi.require_version("Gtk", "4.0")
from gi.repository import Gdk, Gtk, Pango  # noqa: E402

from ..base.i18n import _  # noqa: E402


class Confirm(Gtk.Window):
    """``Confirm(parent, "Delete “x” from the robot?", "Delete", on_yes)``: ``on_yes()`` runs only on
    the action button; ``destructive`` colours it as the theme colours a destructive action."""

    def __init__(
        self,
        parent: Gtk.Window,
        question: str,
        action: str,
        on_yes: Callable[[], None],
        *,
        detail: str = "",
        destructive: bool = True,
    ) -> None:
        super().__init__(title=action, transient_for=parent, modal=True, destroy_with_parent=True)
        self.set_resizable(False)
        self._on_yes = on_yes
        self.answered: bool | None = None
        """True once the action was chosen, False once cancelled (for tests and callers)."""
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=10)
        for side in ("top", "bottom", "start", "end"):
            getattr(box, f"set_margin_{side}")(14)
        self.question = Gtk.Label(label=question, xalign=0.0, wrap=True, max_width_chars=50)
        self.question.set_wrap_mode(Pango.WrapMode.WORD_CHAR)  # a long file name breaks, not the window
        self.question.add_css_class("heading")
        box.append(self.question)
        if detail:
            box.append(Gtk.Label(label=detail, xalign=0.0, wrap=True, max_width_chars=50))
        buttons = Gtk.Box(spacing=8, halign=Gtk.Align.END)
        self.cancel_button = Gtk.Button(label=_("Cancel"))
        self.cancel_button.connect("clicked", lambda _b: self.close())
        self.yes_button = Gtk.Button(label=action)
        self.yes_button.add_css_class("destructive-action" if destructive else "suggested-action")
        self.yes_button.connect("clicked", lambda _b: self._yes())
        buttons.append(self.cancel_button)
        buttons.append(self.yes_button)
        box.append(buttons)
        self.set_child(box)
        keys = Gtk.EventControllerKey()
        keys.connect("key-pressed", self._key)
        self.add_controller(keys)
        self.connect("close-request", self._closing)
        self.set_default_widget(self.cancel_button)  # Enter never deletes by accident

    def _key(self, _c: Gtk.EventControllerKey, keyval: int, _code: int, _state: object) -> bool:
        if keyval == Gdk.KEY_Escape:
            self.close()
            return True
        return False

    def _closing(self, _w: Gtk.Window) -> bool:
        if self.answered is None:
            self.answered = False
        return False

    def _yes(self) -> None:
        self.answered = True
        self.close()
        self._on_yes()

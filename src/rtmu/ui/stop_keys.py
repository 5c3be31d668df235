"""The stop keys on every surface of the window: wherever the keyboard is, Space stops the robot.

GTK hands a key to the surface that holds the keyboard, and only to the widgets of that surface: a
dialog (Turn, Go, the palette, the configuration page, settings, About, the keys window) is a
window of its own, and an open menu or popover is a surface of its own too, so none of their keys
ever reach the main window's key router. Rather than teach each of them about Space, every such
surface gets the same capture-phase key controller when it first shows:

* windows whose ``transient-for`` chain leads to the main window, and popovers whose root is one of
  those windows, are found by one emission hook on ``GtkWidget::show`` — a dialog, menu or drop-down
  added later is covered without a line of its own;
* the controller asks ``control.key_rules.stop_key_action`` what the key does (Space stops, also in a
  text field, where Shift+Space types the space) and calls the window's STOP;
* text fields of a guarded surface say so (``key_rules.FIELD_HINT`` in their placeholder and tooltip);
* an open popover holds the keyboard: held drive keys can no longer be seen let go, so a popover that
  shows ends a held drive first (``on_popover``), as a focus loss does.

The main window itself is guarded too (after its key router: GTK runs a widget's controllers last
added first), so Space behaves the same on every surface: exactly like the STOP button.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable, Iterator

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Gdk", "4.0")
from gi.repository import Gdk, GObject, Gtk  # noqa: E402

from ..base.i18n import _  # noqa: E402
from ..control.key_rules import FIELD_HINT, KeyAction, stop_key_action, stop_key_names  # noqa: E402
from .dialog_chain import belongs_to  # noqa: E402

GUARD_ATTR = "_rtmu_stop_keys"
"""Set on a surface once it carries the stop keys (a surface is guarded once, whichever window asks)."""

_INSTANCES: weakref.WeakSet[StopKeys] = weakref.WeakSet()
_HOOK: list[int] = []


def descendants(widget: Gtk.Widget) -> Iterator[Gtk.Widget]:
    """Every widget below ``widget``, depth first (its popovers included: they are children too).

    One stack, not a generator per level: a nested ``yield from`` passes each widget up through every
    level above it, and the window's 860 widgets took 40 000 steps on every launch."""
    stack: list[Gtk.Widget] = []
    child = widget.get_first_child()
    while child is not None or stack:
        if child is None:
            child = stack.pop().get_next_sibling()
            continue
        yield child
        stack.append(child)
        child = child.get_first_child()


def in_text_field(focus: Gtk.Widget | None) -> bool:
    """The focus is where text is typed (an entry's text, a text view); a spin button takes numbers."""
    if focus is None:
        return False
    if isinstance(focus, Gtk.TextView):
        return True
    if not isinstance(focus, Gtk.Editable | Gtk.Text):
        return False
    parent = focus.get_parent()
    return not isinstance(focus, Gtk.SpinButton) and not isinstance(parent, Gtk.SpinButton)


def is_guarded(native: Gtk.Widget) -> bool:
    return bool(getattr(native, GUARD_ATTR, False))


def _owner_window(native: Gtk.Widget) -> Gtk.Window | None:
    """The window a surface belongs to: itself, or the root of a popover."""
    if isinstance(native, Gtk.Window):
        return native
    root = native.get_root()
    return root if isinstance(root, Gtk.Window) else None


class StopKeys:
    """The stop keys of one main window and of every surface that belongs to it (see the module notes).

    ``stop`` is the window's STOP; ``on_popover`` is told when one of its popovers takes the keyboard.
    """

    def __init__(
        self, window: Gtk.Window, stop: Callable[[], None], on_popover: Callable[[], None] | None = None
    ) -> None:
        self.window = window
        self._stop = stop
        self._on_popover = on_popover
        self.keys = stop_key_names()
        self.stops = 0
        """How many stops the keys made (tests and the report read it)."""
        _INSTANCES.add(self)
        _install_hook()
        self.guard(window)
        for widget in descendants(window):  # popovers built with the window (menus, Go to, the gear)
            if isinstance(widget, Gtk.Popover):
                self.guard(widget, fields=False)  # their fields were marked with the window's

    def close(self) -> None:
        _INSTANCES.discard(self)

    # -- which surfaces --------------------------------------------------------------------
    def owns(self, native: Gtk.Widget) -> bool:
        """``native`` is the main window, one of its dialogs (``transient-for`` chain) or their popover."""
        return belongs_to(self.window, _owner_window(native))

    def guard(self, native: Gtk.Widget, *, fields: bool = True) -> None:
        """Give ``native`` (a window or popover) the stop keys, once; mark its text fields."""
        if not is_guarded(native):
            keys = Gtk.EventControllerKey()
            keys.set_propagation_phase(Gtk.PropagationPhase.CAPTURE)
            keys.connect("key-pressed", self._pressed)
            native.add_controller(keys)
            setattr(native, GUARD_ATTR, True)
            if isinstance(native, Gtk.Window):  # fields built later (the configuration's editors)
                native.connect("notify::focus-widget", lambda w, _p: self.mark_field(w.get_focus()))
        if fields:
            self.mark_fields(native)

    def shown(self, native: Gtk.Widget) -> None:
        """A surface of this window showed (the emission hook): guard it; a popover ends a held drive."""
        self.guard(native)
        if isinstance(native, Gtk.Popover) and self._on_popover is not None:
            self._on_popover()

    @classmethod
    def mark_fields(cls, native: Gtk.Widget) -> None:
        """Text fields say what Space does there (placeholder and tooltip), once each."""
        for widget in descendants(native):
            cls.mark_field(widget)

    @staticmethod
    def mark_field(widget: Gtk.Widget | None) -> None:
        """One text field (or the text inside one) says what Space does there, once."""
        if isinstance(widget, Gtk.Text) and not isinstance(widget.get_parent(), Gtk.SpinButton):
            widget = widget.get_parent()
        if not isinstance(widget, Gtk.Entry | Gtk.SearchEntry | Gtk.PasswordEntry | Gtk.TextView):
            return
        if getattr(widget, GUARD_ATTR, False):
            return
        setattr(widget, GUARD_ATTR, True)
        tip, hint = widget.get_tooltip_text(), _(FIELD_HINT)
        widget.set_tooltip_text(f"{tip}\n{hint}" if tip else hint)
        if isinstance(widget, Gtk.TextView):
            return
        placeholder = widget.get_property("placeholder-text") or ""
        short = _("Space stops")
        widget.set_property("placeholder-text", f"{placeholder} · {short}" if placeholder else hint)

    # -- keys ------------------------------------------------------------------------------
    def _pressed(
        self, controller: Gtk.EventControllerKey, keyval: int, _code: int, state: Gdk.ModifierType
    ) -> bool:
        name = Gdk.keyval_name(Gdk.keyval_to_lower(keyval)) or ""
        if name not in self.keys:
            return False
        widget = controller.get_widget()
        root = widget.get_root() if widget is not None else None
        focus = root.get_focus() if isinstance(root, Gtk.Window) else None
        action = stop_key_action(
            name,
            shift=bool(state & Gdk.ModifierType.SHIFT_MASK),
            ctrl=bool(state & Gdk.ModifierType.CONTROL_MASK),
            alt=bool(state & Gdk.ModifierType.ALT_MASK),
            in_text=in_text_field(focus),
            stop_keys=self.keys,
        )
        if action is not KeyAction.STOP:
            return False
        self.stops += 1
        self._stop()
        return True


def _install_hook() -> None:
    """One ``show`` emission hook for the process: every window and popover that shows is offered to
    the StopKeys whose window it belongs to."""
    if _HOOK:
        return
    Gtk.Label()  # the widget class must be initialised before its signals can be looked up by name
    _HOOK.append(GObject.add_emission_hook(Gtk.Widget, "show", _on_show))


def _on_show(widget: Gtk.Widget, *_args: object) -> bool:
    if isinstance(widget, Gtk.Window | Gtk.Popover):
        for keys in list(_INSTANCES):
            if keys.owns(widget):
                keys.shown(widget)
                break
    return True  # keep the hook

"""Accessible names and descriptions: what a screen reader says for a widget, set where it is built.

GTK 4 gives a button with a text label its name; an icon-only button, a menu button, a drawn gauge or a
box that acts as a button (the D-pad) is announced by its type name ("GtkImage") unless it is named.
These helpers set the properties through ``Gtk.Accessible.update_property`` (GTK 4.8), so each widget
module names its own widgets beside the tooltip, in plain literals: one place per widget.
"""

from __future__ import annotations

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

Prop = Gtk.AccessibleProperty


def spoken(tip: str) -> str:
    """A tooltip as a name: without its key hint (``"Zoom in (Ctrl+plus)"`` → ``"Zoom in"``).

    The tooltip stays the description (GTK reads it), so the key is still said, after the name."""
    head, _, rest = tip.partition(" (")
    return head if rest.endswith(")") else tip


def name(widget: Gtk.Widget, label: str, description: str | None = None) -> None:
    """``widget`` is announced as ``label`` (and ``description``, when given, as its help text)."""
    if description is None:
        widget.update_property([Prop.LABEL], [label])
    else:
        widget.update_property([Prop.LABEL, Prop.DESCRIPTION], [label, description])
    if isinstance(widget, Gtk.DropDown):  # its button, which takes the clicks, is unnamed in GTK 4.8
        name_inner_toggle(widget, label)


def name_menu_button(button: Gtk.MenuButton, label: str) -> None:
    """A menu button; the toggle inside it that takes the clicks (GTK 4.8 exposes both) is labelled by
    it, so it takes the same name, and says that it opens a menu."""
    name(button, label)
    inner = button.get_first_child()
    if inner is not None:
        inner.update_property([Prop.HAS_POPUP], [True])


def describe(widget: Gtk.Widget, description: str) -> None:
    """The words that go with what the widget shows (a state shown by colour, the map's robot)."""
    widget.update_property([Prop.DESCRIPTION], [description])


def value(widget: Gtk.Widget, now: float, low: float, high: float, text: str) -> None:
    """A meter's value as numbers and as words (``12.8 V, low``): a gauge says what its colour says."""
    widget.update_property(
        [Prop.VALUE_MIN, Prop.VALUE_MAX, Prop.VALUE_NOW, Prop.VALUE_TEXT],
        [float(low), float(high), float(now), text],
    )


def mnemonic_button(text: str) -> Gtk.Button:
    """``Gtk.Button.new_with_mnemonic`` named without its underscore: GTK 4.8 names such a button
    ``"_Cancel Cancel"`` (the raw label, then the label), which a screen reader reads out as such."""
    button = Gtk.Button.new_with_mnemonic(text)
    name(button, text.replace("_", ""))
    return button


def name_inner_toggle(widget: Gtk.Widget, label: str) -> None:
    """The button GTK builds inside a drop-down or a combo box with an entry (unnamed in GTK 4.8)."""
    stack = [widget.get_first_child()]
    while stack:
        child = stack.pop()
        while child is not None:
            if isinstance(child, Gtk.ToggleButton):
                name(child, label)
                child.update_property([Prop.HAS_POPUP], [True])
                return
            stack.append(child.get_first_child())
            child = child.get_next_sibling()

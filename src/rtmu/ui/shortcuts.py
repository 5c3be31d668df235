"""The keyboard-shortcuts window, generated from the one key table, ``keys.bindings()``.

The table is the command registry's keys followed by the window's own (zoom, follow, camera page).

GTK 4.8 builds a ``GtkShortcutsWindow`` only from builder XML, so the table is
written out as XML (escaped) and built; a key added to the table shows up here
without a second list to keep in step. Small groups, short columns and at most
two keys per line keep the window inside an 800×480 screen (GTK pages the
columns); the window is built when it is first asked for.
"""

from __future__ import annotations

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gio, Gtk  # noqa: E402

from ..base.i18n import N_, _  # noqa: E402
from .keys import Binding, bindings  # noqa: E402

COLUMN_LINES = 6
"""Lines per column of the shortcuts window: small enough for an 800×480 screen (pages of columns)."""
GROUP_ORDER = (
    N_("Map"),
    N_("Camera head"),
    N_("Window"),
    N_("Navigation"),
    N_("Moves"),
    N_("Fleet"),
    N_("Driving"),
    N_("Connection"),
    N_("Application"),
    N_("Robot"),
    N_("Speed"),
)
"""The order the groups are written in. GTK 4.8's ``GtkShortcutsSection`` re-packs its groups into pages
by their heights and not in the order given; written in this order it shows Driving (the drive keys
and STOP) first on the first page, with the help, Quit and the speed keys (a GUI test checks it on the
real window). Groups not named here come last."""


def shown_accels(b: Binding) -> list[str]:
    """The keys worth printing: no keypad twins, one combination where there are modifiers, at most two.

    The window still answers to every key of the table; the help stays narrow enough for 800 px.
    """
    keys = [a for a in b.accels if "KP_" not in a] or list(b.accels[:1])
    if any("<" in a for a in keys):
        keys = keys[:1]
    return keys[:2]


def shortcuts_xml(table: tuple[Binding, ...] | None = None, column_lines: int = COLUMN_LINES) -> str:
    from xml.sax.saxutils import escape  # (it imports urllib: only when the shortcuts are built)

    found: dict[str, list[Binding]] = {}
    for b in table if table is not None else bindings():
        found.setdefault(b.group, []).append(b)
    rank = {name: i for i, name in enumerate(GROUP_ORDER)}
    groups = dict(sorted(found.items(), key=lambda item: rank.get(item[0], len(rank))))
    out = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        "<interface>",
        '<object class="GtkShortcutsWindow" id="shortcuts">',
        '<property name="modal">1</property>',
        "<child>",
        '<object class="GtkShortcutsSection">',
        '<property name="section-name">main</property>',
        f'<property name="max-height">{column_lines}</property>',
    ]
    for title, items in groups.items():
        out += [
            "<child>",
            '<object class="GtkShortcutsGroup">',
            f'<property name="title">{escape(_(title))}</property>',
        ]
        for b in items:
            accels = " ".join(shown_accels(b)) if b.help is None else b.help
            if not accels:
                continue
            out += [
                "<child>",
                '<object class="GtkShortcutsShortcut">',
                f'<property name="title">{escape(_(b.title))}</property>',
                f'<property name="accelerator">{escape(accels)}</property>',
                "</object>",
                "</child>",
            ]
        out += ["</object>", "</child>"]
    out += ["</object>", "</child>", "</object>", "</interface>"]
    return "\n".join(out)


def build_shortcuts_window() -> Gtk.ShortcutsWindow:
    builder = Gtk.Builder.new_from_string(shortcuts_xml(), -1)
    window = builder.get_object("shortcuts")
    assert isinstance(window, Gtk.ShortcutsWindow)
    _wrap_titles(window)
    return window


def help_overlay_of(window: Gtk.ApplicationWindow) -> Gtk.ShortcutsWindow:
    """The window's shortcuts window, built the first time it is asked for: building it costs every
    launch ~25 ms of CPU before the first map frame, and most runs never open it (issue 28)."""
    shown = Gtk.ApplicationWindow.get_help_overlay(window)
    if shown is None:
        shown = build_shortcuts_window()
        window.set_help_overlay(shown)  # GTK's own win.show-help-overlay takes over from here
    return shown


def install_help_on_demand(window: Gtk.ApplicationWindow) -> None:
    """``win.show-help-overlay`` (F1, Ctrl+?, Help ▸ Keyboard shortcuts) before the window is built."""
    action = Gio.SimpleAction.new("show-help-overlay", None)
    action.connect("activate", lambda _a, _p: help_overlay_of(window).present())
    window.add_action(action)


TITLE_CHARS = 24
"""A shortcut's title wraps at about this many characters: the two columns of a page then fit an
800-pixel screen in a language whose words are longer than English's."""


def _wrap_titles(widget: Gtk.Widget) -> None:
    """GTK sizes each shortcut's title to its whole text; wrapped, a longer language keeps the page's
    columns narrow."""
    child = widget.get_first_child()
    while child is not None:
        if isinstance(child, Gtk.Label) and child.get_ancestor(Gtk.ShortcutsShortcut) is not None:
            child.set_wrap(True)
            child.set_max_width_chars(TITLE_CHARS)
        _wrap_titles(child)
        child = child.get_next_sibling()

"""The command palette (Ctrl+K): the server's own commands, searchable, run without blocking.

It lists what ``listCommands`` / ``listStringCommands`` offer this user (the client core already
left out what the user's groups do not allow), filtered as the operator types; a string command
asks for its argument in its own row. Running hands the command to the network thread and closes
the palette at once, so the keyboard is back on the window for driving; whether the server took it
comes back later as a banner. Names and descriptions are server text: set as plain text, bounded.
"""

from __future__ import annotations

import concurrent.futures
from collections.abc import Callable
from typing import Any

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
gi.require_version("Gdk", "4.0")
from gi.repository import Gdk, GLib, Gtk, Pango  # noqa: E402

from ..base.i18n import _, ngettext  # noqa: E402
from ..client.custom_commands import MAX_ARGUMENT, CommandCatalogue, CustomCommand  # noqa: E402
from . import accessible  # noqa: E402
from .state_words import failure_words  # noqa: E402

ListFn = Callable[[], "concurrent.futures.Future[Any]"]
"""Asks the network thread for the :class:`CommandCatalogue` (``ClientRunner.list_commands``)."""
RunFn = Callable[[CustomCommand, "str | None"], None]
"""Runs one command (the window reports the outcome)."""


class _Row(Gtk.ListBoxRow):
    def __init__(self, command: CustomCommand, run: Callable[[_Row], None]) -> None:
        super().__init__()
        self.command = command
        self.haystack = f"{command.name}\n{command.description}".lower()
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=2)
        box.set_margin_top(4)
        box.set_margin_bottom(4)
        box.set_margin_start(6)
        box.set_margin_end(6)
        name = Gtk.Label(xalign=0.0)
        name.set_text(command.name)
        name.add_css_class("heading")
        name.set_ellipsize(Pango.EllipsizeMode.END)
        box.append(name)
        if command.description:
            about = Gtk.Label(xalign=0.0)
            about.set_text(command.description)
            about.add_css_class("dim-label")
            about.set_wrap(True)
            about.set_wrap_mode(Pango.WrapMode.WORD_CHAR)
            about.set_lines(2)
            about.set_ellipsize(Pango.EllipsizeMode.END)
            about.set_max_width_chars(60)
            box.append(about)
        self.entry: Gtk.Entry | None = None
        if command.takes_argument:
            self.entry = Gtk.Entry(placeholder_text=_("argument, then Enter"))
            self.entry.set_max_length(MAX_ARGUMENT)
            accessible.name(self.entry, _("Argument"))
            self.entry.connect("activate", lambda _e: run(self))
            box.append(self.entry)
        self.set_child(box)


def count_note(shown: int, total: int, hidden: int, search: str) -> str:
    """ "12 commands", "1 of 12 commands" while a search filters them, or why there are none."""
    if not total:
        return _("The server offers this user no commands.")
    if not search.strip():
        note = ngettext("{total} command", "{total} commands", total).format(total=total)
    elif shown:
        note = ngettext("{shown} of {total} command", "{shown} of {total} commands", total).format(
            shown=shown, total=total
        )
    else:
        note = _("No command matches “{strip}” ({total} in all)").format(strip=search.strip(), total=total)
    if hidden:
        note += _(" ({hidden} more the server has are not open to this user)").format(hidden=hidden)
    return note


class CommandPalette(Gtk.Window):
    """See the module notes. ``run(command, argument)`` is called once; the palette then closes."""

    def __init__(self, parent: Gtk.Window, list_commands: ListFn, run: RunFn) -> None:
        super().__init__(title=_("Server commands"), transient_for=parent, modal=True)
        self.set_default_size(520, 420)
        self.set_destroy_with_parent(True)
        self._run = run
        self.catalogue: CommandCatalogue | None = None
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=6)
        box.set_margin_top(8)
        box.set_margin_bottom(8)
        box.set_margin_start(8)
        box.set_margin_end(8)
        self.search = Gtk.SearchEntry(placeholder_text=_("Search the server's commands"))
        self.search.connect("search-changed", lambda _s: self._filter_changed())
        self.search.connect("activate", lambda _s: self._activate_first())
        self.search.connect("stop-search", lambda _s: self.close())
        box.append(self.search)
        self.note = Gtk.Label(label=_("Asking the server for its commands…"), xalign=0.0, wrap=True)
        self.note.add_css_class("dim-label")
        box.append(self.note)
        self.rows = Gtk.ListBox(selection_mode=Gtk.SelectionMode.SINGLE)
        self.rows.set_filter_func(self._matches)
        self.rows.connect("row-activated", lambda _l, row: self._row_activated(row))
        scroller = Gtk.ScrolledWindow(vexpand=True, hscrollbar_policy=Gtk.PolicyType.NEVER)
        scroller.set_child(self.rows)
        box.append(scroller)
        self.set_child(box)
        keys = Gtk.EventControllerKey()
        keys.connect("key-pressed", self._key)
        self.add_controller(keys)
        self.search.grab_focus()
        self.connect("close-request", lambda _w: self._give_back(parent))
        future = list_commands()
        future.add_done_callback(lambda f: GLib.idle_add(self._loaded, f))

    def _give_back(self, parent: Gtk.Window) -> bool:
        """The keyboard goes back to the window (driving) as the palette closes; False: close."""

        def present() -> bool:
            parent.present()
            return False

        GLib.idle_add(present)
        return False

    # -- loading -------------------------------------------------------------------------------
    def _loaded(self, future: concurrent.futures.Future[Any]) -> bool:
        if future.cancelled() or future.exception() is not None:
            error = future.exception()
            self.note.set_text(
                _("The server's commands could not be listed: {value}").format(value=failure_words(error))
            )
            return False
        catalogue = future.result()
        self.show_catalogue(catalogue)
        return False

    def show_catalogue(self, catalogue: CommandCatalogue) -> None:
        self.catalogue = catalogue
        for command in catalogue.commands:
            self.rows.append(_Row(command, self._run_row))
        self._say_count()

    def _say_count(self) -> None:
        """The note under the search: how many commands the list shows now, of how many."""
        catalogue = self.catalogue
        if catalogue is None:
            return
        shown = sum(1 for row in self._rows() if self._matches(row))
        total, search = len(catalogue.commands), self.search.get_text()
        self.note.set_text(count_note(shown, total, catalogue.hidden, search))

    # -- filtering and running -----------------------------------------------------------------
    def _filter_changed(self) -> None:
        self.rows.invalidate_filter()
        self._say_count()

    def _matches(self, row: Gtk.ListBoxRow) -> bool:
        words = self.search.get_text().lower().split()
        return isinstance(row, _Row) and all(w in row.haystack for w in words)

    def visible_names(self) -> list[str]:
        return [row.command.name for row in self._rows() if row.get_child_visible()]

    def _activate_first(self) -> None:
        first = next((row for row in self._rows() if self._matches(row)), None)
        if first is not None:
            self._row_activated(first)

    def _row_activated(self, row: Gtk.ListBoxRow) -> None:
        if not isinstance(row, _Row):
            return
        if row.entry is not None:
            self.rows.select_row(row)
            row.entry.grab_focus()  # a string command asks for its argument first
        else:
            self._run_row(row)

    def _run_row(self, row: _Row) -> None:
        argument = row.entry.get_text() if row.entry is not None else None
        self._run(row.command, argument)
        self.close()

    def _key(self, _c: Gtk.EventControllerKey, keyval: int, _code: int, _state: object) -> bool:
        if keyval == Gdk.KEY_Escape:
            self.close()
            return True
        if keyval == Gdk.KEY_Down and self.search.has_focus():
            first = next((n for n in self._rows() if n.get_child_visible()), None)
            if first is not None:
                self.rows.select_row(first)
                first.grab_focus()
                return True
        return False

    def _rows(self) -> list[_Row]:
        out = []
        row = self.rows.get_first_child()
        while row is not None:
            if isinstance(row, _Row):
                out.append(row)
            row = row.get_next_sibling()
        return out

"""The keys window (Help ▸ Keyboard shortcuts, Ctrl+?, F1): every key the window answers to, in one
column that fits a phone, searchable.

GTK 4.8's ``GtkShortcutsWindow`` lays its pages out in two columns (600 px in English, 700 px in a
longer language), so RTMU draws its own: a search field over one scrolled list of groups, each row the
action's words and its keys as key caps, made from ``keys_sheet.KeySheet`` — the one key table. Typing
anywhere goes to the search; Escape empties the search, or closes the window when the search is empty.
The window belongs to the main window (transient for it), so the stop keys guard it like every dialog
(``stop_keys``): Space stops the robot here too, Shift+Space types a space in the search. It is built
the first time it is asked for and kept, hidden, after.
"""

from __future__ import annotations

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Gdk", "4.0")
gi.require_version("Pango", "1.0")
from gi.repository import Gdk, Gio, GLib, Gtk, Pango  # noqa: E402

from ..base.i18n import _  # noqa: E402
from . import accessible  # noqa: E402
from .keys import bindings  # noqa: E402
from .keys_sheet import KeyRow, KeySheet, count_note  # noqa: E402
from .layout import fit_default_size  # noqa: E402

TITLE_CHARS = 28
"""A row's words wrap at about this many characters, so the key caps keep their room beside them."""


def _caps(chord: tuple[str, ...]) -> Gtk.Box:
    """One chord (keys pressed together) as key caps side by side."""
    box = Gtk.Box(spacing=3, halign=Gtk.Align.END)
    for word in chord:
        cap = Gtk.Label(label=word)
        cap.add_css_class("keycap")
        box.append(cap)
    return box


class Heading(Gtk.Label):
    """A group's heading: the list's header above its first row shown (not a row, so the keyboard
    moves from row to row)."""

    def __init__(self, group: str) -> None:
        super().__init__(label=group, xalign=0.0, wrap=True)
        self.group = group
        self.add_css_class("heading")
        self.set_margin_top(10)
        self.set_margin_bottom(2)


class KeyLine(Gtk.ListBoxRow):
    """A row: the action's words, and its keys — each chord on its line, a run as first … last."""

    def __init__(self, row: KeyRow) -> None:
        super().__init__(activatable=False, selectable=False)
        self.row = row
        box = Gtk.Box(spacing=12)
        for side in ("top", "bottom"):
            getattr(box, f"set_margin_{side}")(4)
        words = Gtk.Label(label=row.title, xalign=0.0, hexpand=True, wrap=True)
        words.set_wrap_mode(Pango.WrapMode.WORD_CHAR)
        words.set_max_width_chars(TITLE_CHARS)
        box.append(words)
        keys = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=3, valign=Gtk.Align.CENTER)
        if row.through:
            run = Gtk.Box(spacing=4, halign=Gtk.Align.END)
            run.append(_caps(row.chords[0]))
            run.append(Gtk.Label(label="…"))
            run.append(_caps(row.chords[-1]))
            keys.append(run)
        else:
            for chord in row.chords:
                keys.append(_caps(chord))
        box.append(keys)
        self.set_child(box)
        accessible.name(self, row.spoken())


class KeysWindow(Gtk.Window):
    """See the module notes. ``sheet``: the rows to list (the window's key table)."""

    def __init__(self, parent: Gtk.Window, sheet: KeySheet) -> None:
        # Not modal: reading the keys never takes the STOP button away from the operator's hand.
        super().__init__(title=_("Keyboard shortcuts"), transient_for=parent, modal=False)
        self.add_css_class("keys-window")
        self.set_titlebar(Gtk.HeaderBar())  # its close button, with or without a window manager (a phone)
        self.set_destroy_with_parent(True)
        self.set_hide_on_close(True)
        fit_default_size(self, 520, 680)
        self.sheet = sheet
        self._shown: set[KeyRow] = set(sheet.rows)
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=6)
        for side in ("top", "bottom", "start", "end"):
            getattr(box, f"set_margin_{side}")(8)
        self.search = Gtk.SearchEntry(placeholder_text=_("Search the keys"))
        accessible.name(self.search, _("Search the keys"))
        self.search.set_key_capture_widget(self)
        self.search.connect("search-changed", lambda _s: self.filter(self.search.get_text()))
        box.append(self.search)
        self.note = Gtk.Label(xalign=0.0, wrap=True, visible=False)
        self.note.add_css_class("dim-label")
        box.append(self.note)
        self.rows = Gtk.ListBox(selection_mode=Gtk.SelectionMode.NONE)
        self.rows.add_css_class("keys-list")
        accessible.name(self.rows, _("Keyboard shortcuts"))
        self.lines = [KeyLine(row) for row in sheet.rows]
        for line in self.lines:
            self.rows.append(line)
        self.rows.set_filter_func(self._keeps)
        self.rows.set_header_func(self._heading)
        scroller = Gtk.ScrolledWindow(vexpand=True, hscrollbar_policy=Gtk.PolicyType.NEVER)
        scroller.set_child(self.rows)
        box.append(scroller)
        self.set_child(box)
        keys = Gtk.EventControllerKey()
        keys.set_propagation_phase(Gtk.PropagationPhase.CAPTURE)
        keys.connect("key-pressed", self._key)
        self.add_controller(keys)
        self.connect("close-request", lambda _w: self._closing(parent))

    def filter(self, query: str) -> None:
        """Show the rows the search leaves, and their headings; say how many when it hides some."""
        kept = self.sheet.matching(query)
        self._shown = set(kept)
        self.rows.invalidate_filter()
        note = count_note(len(kept), len(self.sheet.rows), query)
        self.note.set_text(note)
        self.note.set_visible(bool(note))

    def shown_lines(self) -> list[KeyLine]:
        """The rows the search leaves on the list now."""
        return [line for line in self.lines if line.row in self._shown]

    def _keeps(self, widget: Gtk.ListBoxRow) -> bool:
        return isinstance(widget, KeyLine) and widget.row in self._shown

    @staticmethod
    def _heading(line: Gtk.ListBoxRow, before: Gtk.ListBoxRow | None) -> None:
        """The first row shown of a group carries its heading (the list asks again after a search)."""
        assert isinstance(line, KeyLine)
        group = line.row.group
        header = line.get_header()
        if isinstance(before, KeyLine) and before.row.group == group:
            line.set_header(None)
        elif not (isinstance(header, Heading) and header.group == group):
            line.set_header(Heading(group))

    def _key(self, _c: Gtk.EventControllerKey, keyval: int, _code: int, _state: Gdk.ModifierType) -> bool:
        if keyval != Gdk.KEY_Escape:
            return False
        if self.search.get_text():  # first the search (what was typed is easy to lose), then the window
            self.search.set_text("")
            self.filter("")
            return True
        self.close()
        return True

    def _closing(self, parent: Gtk.Window) -> bool:
        """Hidden, not destroyed: the search starts empty next time; the keyboard goes back to the
        window (driving). False: let GTK hide it."""
        self.search.set_text("")
        self.filter("")  # now, not after the entry's search delay

        def present() -> bool:
            parent.present()
            return False

        GLib.idle_add(present)
        return False


class KeysHelp:
    """``win.show-keys`` on ``window``: its keys window, built the first time it is asked for (most runs
    never open it, and building it costs every launch CPU before the first map frame)."""

    def __init__(self, window: Gtk.ApplicationWindow) -> None:
        self._window = window
        self.shown: KeysWindow | None = None
        action = Gio.SimpleAction.new("show-keys", None)
        action.connect("activate", lambda _a, _p: self.present())
        window.add_action(action)

    def present(self) -> KeysWindow:
        if self.shown is None:
            self.shown = KeysWindow(self._window, KeySheet.of(bindings()))
        self.shown.present()
        self.shown.search.grab_focus()
        return self.shown

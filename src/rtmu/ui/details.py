"""Robot details: the server's status strings, every ``DataStore_*`` value, the docking state, and speech.

A window of its own (from the menu's "Robot details…"), so that typing in the Say field never
reaches the main window's drive keys. The table follows the model: ``RobotState.server_strings``
(``getStrings``, asked for only while this window is open — ``watch(True)`` on opening,
``watch(False)`` on closing) and ``RobotState.data_store``, both refreshed once a second. Server
text is shown as plain text (never markup) and the session has already bounded it; the Say row is
there only when the server lists ``say``.
"""

from __future__ import annotations

from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
from gi.repository import Gdk, Gtk, Pango  # noqa: E402

from ..base.i18n import _  # noqa: E402
from ..model.observables import ConnectionState, RobotModel, RobotState  # noqa: E402
from ..protocol.payloads.ld import data_store_label  # noqa: E402
from ..values.intents import Intent, Say  # noqa: E402
from . import accessible  # noqa: E402

Ask = Callable[[Intent], object]
Watch = Callable[[bool], object]
MAX_SAY = 1000
NAME_CHARS = 28
VALUE_CHARS = 40
"""Widths (characters) past which a row's label and value are ellipsized."""
"""Characters; the entry refuses more."""


class DetailsWindow(Gtk.Window):
    """The details table and the Say field; follows the model while open."""

    def __init__(self, parent: Gtk.Window, model: RobotModel, ask: Ask, watch: Watch | None = None) -> None:
        super().__init__(title=_("Robot details"), transient_for=parent, modal=False)
        self.set_default_size(420, 360)
        self.model = model
        self._ask = ask
        self._watch = watch
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=10)
        for side in ("top", "bottom", "start", "end"):
            getattr(box, f"set_margin_{side}")(14)
        self.grid = Gtk.Grid(column_spacing=16, row_spacing=4)
        scroller = Gtk.ScrolledWindow(vexpand=True)
        scroller.set_child(self.grid)
        box.append(scroller)
        self.none_label = Gtk.Label(label=_("This server publishes no status strings"), xalign=0.0)
        self.none_label.add_css_class("dim-label")
        box.append(self.none_label)
        self.say_row = Gtk.Box(spacing=8)
        self.say_entry = Gtk.Entry(hexpand=True, placeholder_text=_("Text for the robot to say"))
        self.say_entry.set_max_length(MAX_SAY)
        accessible.name(self.say_entry, _("Text for the robot to say"))
        self.say_entry.connect("activate", lambda _e: self.say())
        self.say_button = accessible.mnemonic_button(_("_Say"))
        self.say_button.connect("clicked", lambda _b: self.say())
        self.say_row.append(self.say_entry)
        self.say_row.append(self.say_button)
        box.append(self.say_row)
        self.set_child(box)
        keys = Gtk.EventControllerKey()
        keys.connect("key-pressed", self._key)
        self.add_controller(keys)
        self.values: dict[str, Gtk.Label] = {}
        """Row label text → its value label (what the table shows now)."""
        self.rows: list[tuple[str, str]] = []
        """(label, value) rows in table order (labels may repeat; ``values`` keeps the last)."""
        self._shown: list[Gtk.Label] = []
        self.more_label = Gtk.Label(xalign=0.0)
        self.more_label.add_css_class("dim-label")
        self._unobserve = [
            model.robot.observe(self._on_robot),
            model.connection.observe(self._on_connection),
        ]
        self.connect("close-request", self._closing)
        self._fill(model.robot.value)
        self._on_connection(ConnectionState(), model.connection.value)
        if watch is not None:
            watch(True)

    def _closing(self, _w: Gtk.Window) -> bool:
        for remove in self._unobserve:
            remove()
        self._unobserve = []
        if self._watch is not None:
            self._watch(False)
            self._watch = None
        return False

    def _key(self, _c: Gtk.EventControllerKey, keyval: int, _code: int, _state: object) -> bool:
        if keyval == Gdk.KEY_Escape:
            self.close()
            return True
        return False

    def _on_connection(self, _old: ConnectionState, new: ConnectionState) -> None:
        self.say_row.set_visible("say" in new.offers)

    def _on_robot(self, old: RobotState, new: RobotState) -> None:
        shown = ("data_store", "dock_state", "server_strings", "server_strings_more")
        if any(getattr(new, f) != getattr(old, f) for f in shown):
            self._fill(new)

    def _fill(self, robot: RobotState) -> None:
        rows = [(data_store_label(name), value) for name, value in robot.data_store]
        if robot.dock_state is not None:
            rows.insert(0, (_("Docking"), robot.dock_state))
        rows = list(robot.server_strings) + rows
        more = robot.server_strings_more
        self.more_label.set_text(
            _("… and {more} more the server publishes").format(more=more) if more else ""
        )
        self.more_label.set_visible(bool(more))
        self.none_label.set_visible(not rows)
        if rows == self.rows:
            return
        if [k for k, _value in rows] == [k for k, _value in self.rows]:
            # The same items: change the values in place (once a second while open, no relayout storm).
            for (_name, value), shown in zip(rows, self._shown, strict=True):
                if shown.get_text() != value:
                    shown.set_text(value)
            self.rows = rows
            return
        if self.more_label.get_parent() is not None:
            self.grid.remove(self.more_label)
        child = self.grid.get_first_child()
        while child is not None:
            nxt = child.get_next_sibling()
            self.grid.remove(child)
            child = nxt
        self.values = {}
        self._shown = []
        for i, (label, value) in enumerate(rows):
            name = Gtk.Label(label=label, xalign=0.0, max_width_chars=NAME_CHARS)
            name.set_ellipsize(Pango.EllipsizeMode.END)  # a long server label must not push its value away
            name.add_css_class("dim-label")
            if len(label) > NAME_CHARS:
                name.set_tooltip_text(label)  # plain text, like the label itself
            shown = Gtk.Label(label=value, xalign=0.0, hexpand=True, max_width_chars=VALUE_CHARS)
            shown.set_ellipsize(Pango.EllipsizeMode.END)
            self.grid.attach(name, 0, i, 1, 1)
            self.grid.attach(shown, 1, i, 1, 1)
            self.values[label] = shown
            self._shown.append(shown)
        self.grid.attach(self.more_label, 0, len(rows), 2, 1)
        self.rows = rows

    def say(self) -> None:
        text = self.say_entry.get_text().strip()
        if not text or "say" not in self.model.connection.value.offers:
            return
        try:
            text.encode("latin-1")
        except UnicodeEncodeError:
            self.say_entry.add_css_class("error")
            self.say_entry.set_tooltip_text(_("ARIA strings carry latin-1 characters only"))
            return
        self.say_entry.remove_css_class("error")
        self.say_entry.set_tooltip_text(None)
        self._ask(Say(text))
        self.say_entry.set_text("")

"""Robot details: every ``DataStore_*`` string the server publishes, the docking state, and speech.

A window of its own (from the menu's "Robot details…"), so that typing in the Say field never
reaches the main window's drive keys. The table follows the model (``RobotState.data_store``,
refreshed by the session once a second); the Say row is there only when the server lists ``say``.
"""

from __future__ import annotations

from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gdk, Gtk  # noqa: E402

from ..model import ConnectionState, RobotModel, RobotState  # noqa: E402
from ..protocol.payloads.ld import Say, data_store_label  # noqa: E402

Send = Callable[[str, object], None]
MAX_SAY = 1000
"""Characters; the entry refuses more."""


class DetailsWindow(Gtk.Window):
    """The details table and the Say field; follows the model while open."""

    def __init__(self, parent: Gtk.Window, model: RobotModel, send: Send) -> None:
        super().__init__(title="Robot details", transient_for=parent, modal=False)
        self.set_default_size(420, 360)
        self.model = model
        self._send = send
        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=10)
        for side in ("top", "bottom", "start", "end"):
            getattr(box, f"set_margin_{side}")(14)
        self.grid = Gtk.Grid(column_spacing=16, row_spacing=4)
        scroller = Gtk.ScrolledWindow(vexpand=True)
        scroller.set_child(self.grid)
        box.append(scroller)
        self.none_label = Gtk.Label(label="This server publishes no data-store values", xalign=0.0)
        self.none_label.add_css_class("dim-label")
        box.append(self.none_label)
        self.say_row = Gtk.Box(spacing=8)
        self.say_entry = Gtk.Entry(hexpand=True, placeholder_text="Text for the robot to say")
        self.say_entry.set_max_length(MAX_SAY)
        self.say_entry.connect("activate", lambda _e: self.say())
        self.say_button = Gtk.Button.new_with_mnemonic("_Say")
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
        self._unobserve = [
            model.robot.observe(self._on_robot),
            model.connection.observe(self._on_connection),
        ]
        self.connect("close-request", self._closing)
        self._fill(model.robot.value)
        self._on_connection(ConnectionState(), model.connection.value)

    def _closing(self, _w: Gtk.Window) -> bool:
        for remove in self._unobserve:
            remove()
        self._unobserve = []
        return False

    def _key(self, _c: Gtk.EventControllerKey, keyval: int, _code: int, _state: object) -> bool:
        if keyval == Gdk.KEY_Escape:
            self.close()
            return True
        return False

    def _on_connection(self, _old: ConnectionState, new: ConnectionState) -> None:
        self.say_row.set_visible("say" in new.offers)

    def _on_robot(self, old: RobotState, new: RobotState) -> None:
        if (new.data_store, new.dock_state) != (old.data_store, old.dock_state):
            self._fill(new)

    def _fill(self, robot: RobotState) -> None:
        rows = [(data_store_label(name), value) for name, value in robot.data_store]
        if robot.dock_state is not None:
            rows.insert(0, ("Docking", robot.dock_state))
        if [(k, v.get_text()) for k, v in self.values.items()] == rows:
            return
        child = self.grid.get_first_child()
        while child is not None:
            nxt = child.get_next_sibling()
            self.grid.remove(child)
            child = nxt
        self.values = {}
        for i, (label, value) in enumerate(rows):
            name = Gtk.Label(label=label, xalign=0.0)
            name.add_css_class("dim-label")
            shown = Gtk.Label(label=value, xalign=0.0, hexpand=True)
            self.grid.attach(name, 0, i, 1, 1)
            self.grid.attach(shown, 1, i, 1, 1)
            self.values[label] = shown
        self.none_label.set_visible(not robot.data_store)

    def say(self) -> None:
        text = self.say_entry.get_text().strip()
        if not text or "say" not in self.model.connection.value.offers:
            return
        try:
            text.encode("latin-1")
        except UnicodeEncodeError:
            self.say_entry.add_css_class("error")
            self.say_entry.set_tooltip_text("ARIA strings carry latin-1 characters only")
            return
        self.say_entry.remove_css_class("error")
        self.say_entry.set_tooltip_text(None)
        self._send("say", Say(text))
        self.say_entry.set_text("")

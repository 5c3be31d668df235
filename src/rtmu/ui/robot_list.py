"""The robot list: one row per robot of the fleet — colour, name, mode and status, battery, link.

Clicking (or tapping) a row selects that robot; the fleet stops the robot selected
before (``Fleet.select``). A wide window shows the list as a sidebar beside the map;
a narrow one (under :data:`NARROW_PX`) as a strip under it that a button folds away
(``set_narrow``). Server strings are shown as plain text, cut to :data:`MAX_TEXT`
characters. A robot whose link is not OK shows it in its row (greyed, the reason in
words) while the others carry on. The list is never focusable: the keyboard stays
with driving.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk, Pango  # noqa: E402

from ..fleet.sessions import RobotSession  # noqa: E402
from ..model.observables import LinkLevel, Phase, RobotState  # noqa: E402
from .fleet_draw import RGB  # noqa: E402

NARROW_PX = 640
"""Windows narrower than this get the list as a foldable strip under the map."""
MAX_TEXT = 60
SIDEBAR_PX = 210


def _short(text: str) -> str:
    text = "".join(ch if ch.isprintable() else " " for ch in text).strip()
    return text if len(text) <= MAX_TEXT else text[: MAX_TEXT - 1] + "…"


@dataclass(frozen=True, slots=True)
class RowText:
    """What one row says (the GTK-free part: tests and the bench compare these)."""

    name: str
    detail: str
    battery: str
    link: str
    stale: bool


def row_text(session: RobotSession) -> RowText:
    state = session.state
    r: RobotState = state.robot.value
    conn = state.connection.value
    health = state.health.value
    words = [w for w in (_short(r.mode_name or r.mode), _short(r.status)) if w]
    if r.battery_v is None:
        battery = ""
    elif r.battery_is_soc:
        battery = f"{r.battery_v:.0f} %"
    else:
        battery = f"{r.battery_v:.1f} V"
    if conn.phase is Phase.CONNECTED:
        link = {LinkLevel.OK: "link ok", LinkLevel.STALE: "link stale", LinkLevel.LOST: "link lost"}.get(
            health.level, "connected"
        )
    else:
        link = {
            Phase.DISCONNECTED: "not connected",
            Phase.CONNECTING: "connecting…",
            Phase.RECONNECTING: "link lost — reconnecting",
            Phase.FAILED: "link lost" if conn.error else "failed",
        }[conn.phase]
    stale = conn.phase is not Phase.CONNECTED or health.level is not LinkLevel.OK
    return RowText(_short(session.name), " · ".join(words) or "—", battery, link, stale)


class _Row(Gtk.ListBoxRow):
    def __init__(self, session: RobotSession, rgb: RGB) -> None:
        super().__init__()
        self.session = session
        self.rgb = rgb
        self.set_focusable(False)
        self.add_css_class("robot-row")
        box = Gtk.Box(spacing=8, margin_top=4, margin_bottom=4, margin_start=6, margin_end=6)
        self.swatch = Gtk.DrawingArea(content_width=14, content_height=14, valign=Gtk.Align.CENTER)
        self.swatch.set_draw_func(self._draw_swatch)
        box.append(self.swatch)
        text = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, hexpand=True)
        top = Gtk.Box(spacing=6)
        self.name = self._label(top, "robot-name", expand=True)
        self.battery = self._label(top, "robot-battery")
        text.append(top)
        self.detail = self._label(text, "robot-detail")
        self.link = self._label(text, "robot-link")
        box.append(text)
        self.set_child(box)
        self.shown: RowText | None = None
        self.update()

    @staticmethod
    def _label(parent: Gtk.Box, css: str, *, expand: bool = False) -> Gtk.Label:
        label = Gtk.Label(xalign=0.0, hexpand=expand, use_markup=False)
        label.set_ellipsize(Pango.EllipsizeMode.END)
        label.add_css_class(css)
        parent.append(label)
        return label

    def _draw_swatch(self, _area: Gtk.DrawingArea, ctx: object, width: int, height: int) -> None:
        grey = self.shown is not None and self.shown.stale
        ctx.set_source_rgb(*((0.6, 0.61, 0.64) if grey else self.rgb))  # type: ignore[attr-defined]
        ctx.arc(width / 2, height / 2, min(width, height) / 2, 0, 2 * math.pi)  # type: ignore[attr-defined]
        ctx.fill()  # type: ignore[attr-defined]

    def update(self) -> None:
        text = row_text(self.session)
        if text == self.shown:
            return
        was_stale = self.shown.stale if self.shown is not None else None
        self.shown = text
        self.name.set_text(text.name)
        self.detail.set_text(text.detail)
        self.battery.set_text(text.battery)
        self.link.set_text(text.link)
        if text.stale != was_stale:
            (self.add_css_class if text.stale else self.remove_css_class)("robot-stale")
            self.swatch.queue_draw()


class RobotList(Gtk.Box):
    """See the module notes. ``select(session)`` is the fleet's selection; ``colour(session)`` its colour."""

    def __init__(self, select: Callable[[RobotSession], None], colour: Callable[[RobotSession], RGB]) -> None:
        super().__init__(orientation=Gtk.Orientation.VERTICAL)
        self.add_css_class("robot-list")
        self._select = select
        self._colour = colour
        self.fold = Gtk.ToggleButton(label="Robots", active=True, visible=False)
        self.fold.set_focusable(False)
        self.fold.connect("toggled", lambda b: self.revealer.set_reveal_child(b.get_active()))
        self.append(self.fold)
        self.listbox = Gtk.ListBox(selection_mode=Gtk.SelectionMode.SINGLE)
        self.listbox.set_focusable(False)
        self.listbox.connect("row-activated", self._activated)
        self.listbox.set_activate_on_single_click(True)
        self.scroller = Gtk.ScrolledWindow(vexpand=True, propagate_natural_height=True)
        self.scroller.set_policy(Gtk.PolicyType.NEVER, Gtk.PolicyType.AUTOMATIC)
        self.scroller.set_child(self.listbox)
        self.scroller.set_focusable(False)
        self.revealer = Gtk.Revealer(reveal_child=True, vexpand=True)
        self.revealer.set_child(self.scroller)
        self.append(self.revealer)
        self.rows: dict[int, _Row] = {}
        self._syncing = False
        self.set_narrow(False)

    def set_sessions(self, sessions: tuple[RobotSession, ...], selected: RobotSession | None) -> None:
        """Show exactly ``sessions`` (in order), with ``selected`` highlighted."""
        wanted = {id(s) for s in sessions}
        for key in [k for k in self.rows if k not in wanted]:
            self.listbox.remove(self.rows.pop(key))
        for session in sessions:
            if id(session) not in self.rows:
                row = _Row(session, self._colour(session))
                self.rows[id(session)] = row
                self.listbox.append(row)
        self.fold.set_label(f"Robots ({len(sessions)})")
        self.show_selected(selected)

    def show_selected(self, selected: RobotSession | None) -> None:
        row = self.rows.get(id(selected)) if selected is not None else None
        self._syncing = True
        try:
            if row is None:
                self.listbox.unselect_all()
            else:
                self.listbox.select_row(row)
        finally:
            self._syncing = False

    def refresh(self, session: RobotSession | None = None) -> None:
        """Update one robot's row (or all): only rows whose text changed touch GTK."""
        rows = (
            self.rows.values()
            if session is None
            else [self.rows[id(session)]]
            if id(session) in self.rows
            else []
        )
        for row in rows:
            row.update()

    def row_of(self, session: RobotSession) -> _Row | None:
        return self.rows.get(id(session))

    def set_narrow(self, narrow: bool) -> None:
        """Sidebar (wide window) or a strip under the map that the Robots button folds (narrow)."""
        self.fold.set_visible(narrow)
        if narrow:
            self.set_size_request(-1, -1)
            self.scroller.set_max_content_height(120)
            self.scroller.set_vexpand(False)
            self.revealer.set_vexpand(False)
        else:
            self.fold.set_active(True)
            self.revealer.set_reveal_child(True)
            self.set_size_request(SIDEBAR_PX, -1)
            self.scroller.set_max_content_height(-1)
            self.scroller.set_vexpand(True)
            self.revealer.set_vexpand(True)

    def _activated(self, _listbox: Gtk.ListBox, row: Gtk.ListBoxRow) -> None:
        if not self._syncing and isinstance(row, _Row):
            self._select(row.session)

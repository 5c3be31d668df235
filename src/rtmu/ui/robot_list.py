"""The robot list: one row per listed robot — colour, name, mode and status, battery, link.

Clicking (or tapping) a row selects that robot; the fleet stops the robot selected
before (``Fleet.select``) and connects one that was only listed (``Fleet.select_named``:
a central server may list a thousand robots, of which the window keeps
``connect_at_most`` connected). Only the rows on screen are built: the list is a
``Gtk.ListView`` over the robots' names, its row widgets recycled as it scrolls, so
10 000 listed robots cost no more widgets than 20. A wide window shows the list as a
sidebar beside the map; a narrow one (under :data:`NARROW_PX`) as a strip under it
that a button folds away (``set_narrow``). Server strings are shown as plain text,
cut to :data:`MAX_TEXT` characters. A robot whose link is not OK — or that is not
connected — shows it in its row (greyed, the reason in words) while the others carry
on. The list never takes the keyboard: the keys stay with driving.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gio, GObject, Gtk, Pango  # noqa: E402

from ..base.i18n import N_, _, number  # noqa: E402
from ..fleet.sessions import RobotSession  # noqa: E402
from ..model.observables import LinkLevel, Phase, RobotState  # noqa: E402
from .fleet_draw import RGB  # noqa: E402

NARROW_PX = 640
"""Windows narrower than this get the list as a foldable strip under the map."""
MAX_TEXT = 60
SIDEBAR_PX = 210
UNCONNECTED_RGB: RGB = (0.6, 0.61, 0.64)
NOT_CONNECTED = N_("not connected — select to connect")


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
        battery = _("{percent} %").format(percent=number(r.battery_v))
    else:
        battery = _("{volts} V").format(volts=number(r.battery_v, 1))
    if conn.phase is Phase.CONNECTED:
        link = {
            LinkLevel.OK: _("link ok"),
            LinkLevel.STALE: _("link stale"),
            LinkLevel.LOST: _("link lost"),
        }.get(health.level, _("connected"))
    else:
        link = {
            Phase.DISCONNECTED: _("not connected"),
            Phase.CONNECTING: _("connecting…"),
            Phase.RECONNECTING: _("link lost — reconnecting"),
            Phase.FAILED: _("link lost") if conn.error else _("failed"),
        }[conn.phase]
    stale = conn.phase is not Phase.CONNECTED or health.level is not LinkLevel.OK
    return RowText(_short(session.name), " · ".join(words) or "—", battery, link, stale)


def listed_row_text(name: str) -> RowText:
    """The row of a robot the roster lists but the window has not connected to."""
    return RowText(_short(name), "—", "", _(NOT_CONNECTED), True)


class RobotItem(GObject.Object):
    """One listed robot in the list's model: its name (its session, if any, is looked up by it)."""

    __gtype_name__ = "RtmuRobotItem"

    def __init__(self, name: str) -> None:
        super().__init__()
        self.name = name


class _Row(Gtk.Box):
    """The widget that shows one robot; recycled by the list view for whichever robot scrolls in."""

    def __init__(self, robots: RobotList) -> None:
        super().__init__(spacing=8, margin_top=4, margin_bottom=4, margin_start=6, margin_end=6)
        self.robots = robots
        self.item: RobotItem | None = None
        self.session: RobotSession | None = None
        self.rgb: RGB = UNCONNECTED_RGB
        self.add_css_class("robot-row")
        self.swatch = Gtk.DrawingArea(content_width=14, content_height=14, valign=Gtk.Align.CENTER)
        self.swatch.set_draw_func(self._draw_swatch)
        self.append(self.swatch)
        text = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, hexpand=True)
        top = Gtk.Box(spacing=6)
        self.name = self._label(top, "robot-name", expand=True)
        self.battery = self._label(top, "robot-battery")
        text.append(top)
        self.detail = self._label(text, "robot-detail")
        self.link = self._label(text, "robot-link")
        self.append(text)
        self.shown: RowText | None = None
        self.selected = False
        click = Gtk.GestureClick()
        click.connect("released", lambda _g, _n, _x, _y: self._clicked())
        self.add_controller(click)

    @staticmethod
    def _label(parent: Gtk.Box, css: str, *, expand: bool = False) -> Gtk.Label:
        label = Gtk.Label(xalign=0.0, hexpand=expand, use_markup=False)
        label.set_ellipsize(Pango.EllipsizeMode.END)
        label.add_css_class(css)
        parent.append(label)
        return label

    def _draw_swatch(self, _area: Gtk.DrawingArea, ctx: object, width: int, height: int) -> None:
        grey = self.shown is not None and self.shown.stale
        ctx.set_source_rgb(*(UNCONNECTED_RGB if grey else self.rgb))  # type: ignore[attr-defined]
        ctx.arc(width / 2, height / 2, min(width, height) / 2, 0, 2 * math.pi)  # type: ignore[attr-defined]
        ctx.fill()  # type: ignore[attr-defined]

    def _clicked(self) -> None:
        if self.item is not None:
            self.robots.clicked(self.item.name)

    def bind(self, item: RobotItem | None) -> None:
        self.item = item
        self.shown = None
        self.update()

    def update(self) -> None:
        item = self.item
        if item is None:
            self.session = None
            return
        session = self.robots.session_of(item.name)
        self.session = session
        if session is not None:
            self.rgb = self.robots.colour_of(session)
            text = row_text(session)
        else:
            self.rgb = UNCONNECTED_RGB
            text = listed_row_text(item.name)
        selected = self.robots.selected_name == item.name
        if selected != self.selected:
            self.selected = selected
            (self.add_css_class if selected else self.remove_css_class)("robot-selected")
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
    """See the module notes. ``select(name)`` selects (and connects) a robot; ``session_of(name)`` is
    its session if connected; ``colour(session)`` its colour."""

    def __init__(
        self,
        select: Callable[[str], object],
        colour: Callable[[RobotSession], RGB],
        session_of: Callable[[str], RobotSession | None],
    ) -> None:
        super().__init__(orientation=Gtk.Orientation.VERTICAL)
        self.add_css_class("robot-list")
        self._select = select
        self.colour_of = colour
        self.session_of = session_of
        self.selected_name: str | None = None
        self.names: tuple[str, ...] = ()
        self._items: list[RobotItem] = []
        self.bound: set[_Row] = set()
        """The row widgets on screen now (the list view builds only those)."""
        self.fold = Gtk.ToggleButton(label=_("Robots"), active=True, visible=False)
        self.fold.set_focusable(False)
        self.fold.connect("toggled", lambda b: self.revealer.set_reveal_child(b.get_active()))
        self.append(self.fold)
        self.store = Gio.ListStore(item_type=RobotItem)
        factory = Gtk.SignalListItemFactory()
        factory.connect("setup", self._setup)
        factory.connect("bind", self._bind)
        factory.connect("unbind", self._unbind)
        self.view = Gtk.ListView(model=Gtk.NoSelection(model=self.store), factory=factory)
        self.view.add_css_class("robot-rows")
        self.view.set_can_focus(False)  # neither the view nor any row takes the keyboard
        self.scroller = Gtk.ScrolledWindow(vexpand=True, propagate_natural_height=True)
        self.scroller.set_policy(Gtk.PolicyType.NEVER, Gtk.PolicyType.AUTOMATIC)
        self.scroller.set_child(self.view)
        self.scroller.set_can_focus(False)
        self.revealer = Gtk.Revealer(reveal_child=True, vexpand=True)
        self.revealer.set_child(self.scroller)
        self.append(self.revealer)
        self.set_narrow(False)

    # -- the list view's rows ------------------------------------------------------------------
    def _setup(self, _factory: Gtk.SignalListItemFactory, list_item: Gtk.ListItem) -> None:
        list_item.set_activatable(False)
        list_item.set_selectable(False)
        list_item.set_child(_Row(self))

    def _bind(self, _factory: Gtk.SignalListItemFactory, list_item: Gtk.ListItem) -> None:
        row = list_item.get_child()
        item = list_item.get_item()
        if isinstance(row, _Row) and isinstance(item, RobotItem):
            row.bind(item)
            self.bound.add(row)

    def _unbind(self, _factory: Gtk.SignalListItemFactory, list_item: Gtk.ListItem) -> None:
        row = list_item.get_child()
        if isinstance(row, _Row):
            row.bind(None)
            self.bound.discard(row)

    # -- what it shows -------------------------------------------------------------------------
    def set_names(self, names: Sequence[str]) -> None:
        """Show exactly these robots, in this order (a grown list only appends: no rebuild)."""
        names = tuple(names)
        if names == self.names:
            return
        old = self.names
        if names[: len(old)] == old:
            new = [RobotItem(n) for n in names[len(old) :]]
            self.store.splice(len(old), 0, new)
            self._items.extend(new)
        else:
            self._items = [RobotItem(n) for n in names]
            self.store.splice(0, len(old), self._items)
        self.names = names
        self.fold.set_label(_("Robots ({len})").format(len=len(names)))

    def show_selected(self, name: str | None) -> None:
        self.selected_name = name
        self.refresh()

    def refresh(self) -> None:
        """Update the rows on screen: only text that changed touches GTK."""
        for row in list(self.bound):
            row.update()

    def row_of(self, session: RobotSession) -> _Row | None:
        """The row on screen that shows ``session`` (None when it is scrolled away or not listed)."""
        return next((r for r in self.bound if r.item is not None and r.item.name == session.name), None)

    def row_named(self, name: str) -> _Row | None:
        return next((r for r in self.bound if r.item is not None and r.item.name == name), None)

    def clicked(self, name: str) -> None:
        self._select(name)

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

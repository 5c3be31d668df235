"""The routes button of LD robots: a header-bar button whose popover lists routes and goals.

Shown only while the connected server lists ``getRoutes`` or ``gotoRouteGoal``. Each route has a
Patrol button that sends ``patrol`` (only when listed, too); each of the map's goals (``getGoals``,
asked for only where ``gotoRouteGoal`` is listed) has a Go button that sends ``gotoRouteGoal``.
The popover holds buttons only, no text fields, so the window's drive keys keep working as
everywhere else. Names come from the model (``RobotState.routes`` / ``goals``), which the session
fills from ``getRoutes`` / ``routesUpdated`` and ``getGoals`` / ``goalsUpdated``.
"""

from __future__ import annotations

from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

from ..base.i18n import _  # noqa: E402
from ..model.observables import ConnectionState, Phase, RobotModel  # noqa: E402
from ..values.intents import GotoGoal, Intent, Patrol  # noqa: E402
from . import accessible  # noqa: E402

Ask = Callable[[Intent], object]
"""The selected robot's intents (``SelectedRobot.ask``): through its controller's guard."""


class RoutesPanel(Gtk.MenuButton):
    """Header-bar button + popover listing routes, each with Patrol."""

    def __init__(self, model: RobotModel, ask: Ask) -> None:
        super().__init__(icon_name="mark-location-symbolic", tooltip_text=_("Routes (patrol)"))
        accessible.name_menu_button(self, _("Routes"))
        self.set_focusable(False)
        inner = self.get_first_child()
        if inner is not None:
            inner.set_focusable(False)  # keys go to the window's router, as for the menu button
        self.model = model
        self._ask = ask
        self.list = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=4)
        for side in ("top", "bottom", "start", "end"):
            getattr(self.list, f"set_margin_{side}")(8)
        self.empty = Gtk.Label(label=_("This map has no routes"), xalign=0.0)
        self.empty.add_css_class("dim-label")
        self.rows: dict[str, Gtk.Button] = {}
        """Route name → its Patrol button (what is shown now)."""
        self.goal_rows: dict[str, Gtk.Button] = {}
        """Goal name → its Go button (``gotoRouteGoal``)."""
        popover = Gtk.Popover()
        popover.set_child(self.list)
        self.set_popover(popover)
        self._shown: tuple[tuple[str, ...], tuple[str, ...]] | None = None
        self._unobserve = [
            model.robot.observe(lambda _o, _n: self._refill()),
            model.navigation.observe(lambda _o, _n: self._refill()),
            model.connection.observe(self._on_connection),
        ]
        self._on_connection(ConnectionState(), model.connection.value)
        self._refill()

    def close(self) -> None:
        for remove in self._unobserve:
            remove()
        self._unobserve = []

    def _on_connection(self, _old: ConnectionState, new: ConnectionState) -> None:
        connected = new.phase is Phase.CONNECTED
        self.set_visible(connected and ("getRoutes" in new.offers or "gotoRouteGoal" in new.offers))
        for button in self.rows.values():
            button.set_sensitive(connected and "patrol" in new.offers)
        for button in self.goal_rows.values():
            button.set_sensitive(connected and "gotoRouteGoal" in new.offers)

    def _refill(self) -> None:
        """Routes are the robot's; goals the map's one list (``NavState.goals``)."""
        self._fill(self.model.robot.value.routes, self.model.navigation.value.goals)

    def _fill(self, routes: tuple[str, ...], goals: tuple[str, ...] = ()) -> None:
        if (routes, goals) == self._shown:
            return
        self._shown = (routes, goals)
        child = self.list.get_first_child()
        while child is not None:
            nxt = child.get_next_sibling()
            self.list.remove(child)
            child = nxt
        self.rows = {}
        self.goal_rows = {}
        self._fill_goals(goals)
        if not routes:
            self.list.append(self.empty)
            return
        can_patrol = "patrol" in self.model.connection.value.offers
        for name in routes:
            row = Gtk.Box(spacing=8)
            label = Gtk.Label(label=name, xalign=0.0, hexpand=True)
            button = Gtk.Button.new_with_label(_("Patrol"))
            button.set_tooltip_text(
                _("Patrol the route {name!r} (the robot drives by itself; STOP ends it)").format(name=name)
            )
            button.set_sensitive(can_patrol)
            button.connect("clicked", lambda _b, n=name: self.patrol(n))
            row.append(label)
            row.append(button)
            self.list.append(row)
            self.rows[name] = button

    def _fill_goals(self, goals: tuple[str, ...]) -> None:
        if not goals:
            return
        title = Gtk.Label(label=_("Goals"), xalign=0.0)
        title.add_css_class("heading")
        self.list.append(title)
        can_go = "gotoRouteGoal" in self.model.connection.value.offers
        for name in goals:
            row = Gtk.Box(spacing=8)
            button = Gtk.Button.new_with_label(_("Go"))
            button.set_tooltip_text(
                _("Drive to the goal {name!r} (the robot drives by itself; STOP ends it)").format(name=name)
            )
            button.set_sensitive(can_go)
            button.connect("clicked", lambda _b, n=name: self.go_to_goal(n))
            row.append(Gtk.Label(label=name, xalign=0.0, hexpand=True))
            row.append(button)
            self.list.append(row)
            self.goal_rows[name] = button
        routes_title = Gtk.Label(label=_("Routes"), xalign=0.0)
        routes_title.add_css_class("heading")
        self.list.append(routes_title)

    def go_to_goal(self, goal: str) -> None:
        if "gotoRouteGoal" in self.model.connection.value.offers:
            self._ask(GotoGoal(goal, route=True))
            popover = self.get_popover()
            if popover is not None:
                popover.popdown()

    def patrol(self, route: str) -> None:
        if "patrol" in self.model.connection.value.offers:
            self._ask(Patrol(route))
            popover = self.get_popover()
            if popover is not None:
                popover.popdown()

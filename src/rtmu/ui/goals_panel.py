"""The header's "Go to" button (an arrow icon): a popover to send the robot somewhere.

A search field over the map's goals (``NavState.goals``, which the session refreshes on
``goalsUpdated``): choosing one calls ``controller.goto_goal``. Below it, what else navigation
offers — Go home, Dock and charge, Tour the goals (registry commands, run through the window so
a disabled one says why), and the two map modes, Go to a point and Set robot position. Whatever the
server does not list stays visible but greyed, with the reason under it: the operator learns what
this robot cannot do instead of looking for it.

Shown only while the connected server navigates in some way. The popover is a surface of its own:
its keys do not reach the window's key router, so typing in the search field types and arrows move
in the list, while the stop keys (Space) stop the robot there as on every surface of the window
(``stop_keys``) — also mid-navigation, also mid-word. Goal names are plain text; the goal being
driven to is marked. Ctrl+G opens it from the keyboard (``keyboard_nav``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import gi

gi.require_version("Gtk", "4.0")
gi.require_version("Pango", "1.0")
from gi.repository import Gtk, Pango  # noqa: E402

from ..base.i18n import N_, _  # noqa: E402
from ..control.commands import COMMANDS, CommandState  # noqa: E402
from ..model.observables import ConnectionState, NavState, Phase, RobotModel  # noqa: E402
from . import accessible  # noqa: E402
from .nav_draw import MarkerKind  # noqa: E402
from .state_words import reason_words  # noqa: E402

NAV_OFFERS = ("gotoGoal", "gotoRouteGoal", "gotoPose", "home", "dock", "tourGoals", "localizeToPose")
"""The panel shows while the server lists any of these."""
COMMANDS_SHOWN = {"home": N_("Go home"), "dock": N_("Dock"), "tour_goals": N_("Tour goals")}
"""Registry commands shown as buttons, with the short label that keeps the popover within 800 px."""
MODES = (
    (MarkerKind.GOTO, N_("Go to point…"), "gotoPose", N_("Click the map where the robot should go")),
    (MarkerKind.LOCALIZE, N_("Set position…"), "localizeToPose", N_("Tell the robot where it is on the map")),
)
NOT_OFFERED = N_("not offered by the server")


def _matches(query: str, name: str) -> bool:
    """The query appears in the name, ignoring case and spaces (Space is STOP, even while typing)."""
    return "".join(query.casefold().split()) in "".join(name.casefold().split())


class GoalsPanel(Gtk.MenuButton):
    """See the module notes. ``goto(name)``, ``run(command)`` and ``pick(kind)`` are the window's."""

    def __init__(
        self,
        model: RobotModel,
        *,
        goto: Callable[[str], None],
        run: Callable[[str], None],
        pick: Callable[[MarkerKind], None],
    ) -> None:
        super().__init__(tooltip_text=_("Send the robot somewhere: goals, a point, home, the dock"))
        self.set_icon_name("go-jump-symbolic")  # an icon: the header must still fit a 560 px window
        accessible.name_menu_button(self, _("Go to"))
        self.add_css_class("goals-button")
        self.model = model
        self._goto, self._run, self._pick = goto, run, pick
        self._states: dict[str, CommandState] = {}

        box = Gtk.Box(orientation=Gtk.Orientation.VERTICAL, spacing=6)
        for side in ("top", "bottom", "start", "end"):
            getattr(box, f"set_margin_{side}")(6)
        self.search = Gtk.SearchEntry(placeholder_text=_("Search goals"))
        # A placeholder is no name: GTK 4.8 would read the field as "GtkSearchEntry".
        accessible.name(self.search, _("Search goals"))
        self.search.connect("search-changed", lambda _e: self._filter())
        self.search.connect("activate", lambda _e: self.choose_first())
        self.search.connect("stop-search", lambda _e: self.popdown())
        box.append(self.search)
        self.list = Gtk.ListBox(selection_mode=Gtk.SelectionMode.NONE)
        accessible.name(self.list, _("Goals"))
        self.list.add_css_class("goal-list")
        self.list.set_activate_on_single_click(True)
        self.list.connect("row-activated", lambda _l, row: self.choose(row.goal))
        self.list.set_filter_func(lambda row: _matches(self.search.get_text(), row.goal))
        scroller = Gtk.ScrolledWindow(hscrollbar_policy=Gtk.PolicyType.NEVER)
        scroller.set_propagate_natural_height(True)
        scroller.set_max_content_height(190)  # an 800×480 screen keeps the buttons below in view
        scroller.set_min_content_width(220)
        scroller.set_child(self.list)
        box.append(scroller)
        self.empty = Gtk.Label(label=_("This map has no goals"), xalign=0.0)
        self.empty.add_css_class("dim-label")
        box.append(self.empty)
        self.rows: dict[str, Gtk.ListBoxRow] = {}
        """Goal name → its row (what is shown now)."""

        self._tips: dict[str, str] = {}
        self.buttons: dict[str, Gtk.Button] = {}
        """Command or mode name (``home``, ``dock``, ``tour_goals``, ``goto``, ``localize``) → button."""
        commands = Gtk.Box(spacing=4, homogeneous=True)
        for name, short in COMMANDS_SHOWN.items():
            button = Gtk.Button(label=_(short))
            button.connect("clicked", lambda _b, n=name: self._command(n))
            commands.append(button)
            self.buttons[name] = button
            full = _(COMMANDS.get(name).label) if name in COMMANDS else short
            self._tips[name] = _("{full}: the robot drives by itself; STOP ends it").format(full=full)
        modes = Gtk.Box(spacing=4, homogeneous=True)
        for kind, label, _data, tip in MODES:
            button = Gtk.Button(label=_(label))
            button.connect("clicked", lambda _b, k=kind: self._mode(k))
            modes.append(button)
            self.buttons[kind.value] = button
            self._tips[kind.value] = _(tip)
        box.append(commands)
        box.append(modes)
        self.reasons = Gtk.Label(xalign=0.0, wrap=True, max_width_chars=36, visible=False)
        self.reasons.add_css_class("dim-label")
        self.reasons.add_css_class("caption")
        self.reasons.set_use_markup(False)
        self.reasons.set_wrap_mode(Pango.WrapMode.WORD_CHAR)
        box.append(self.reasons)
        popover = Gtk.Popover()
        popover.set_child(box)
        popover.connect("show", lambda _p: self._opened())
        self.set_popover(popover)

        self._goals: tuple[str, ...] | None = None
        self._current = ""
        self._unobserve = [
            model.navigation.observe(self._on_nav),
            model.connection.observe(self._on_connection),
        ]
        self._on_connection(ConnectionState(), model.connection.value)
        self._on_nav(NavState(), model.navigation.value)

    def close(self) -> None:
        self.popdown()  # an open popover keeps the keyboard grabbed past its window
        for remove in self._unobserve:
            remove()
        self._unobserve = []

    # -- choosing ----------------------------------------------------------------------------
    def choose(self, goal: str) -> None:
        self.popdown()
        self._goto(goal)

    def choose_first(self) -> None:
        """Enter in the search field: the first goal that matches."""
        for name, row in self.rows.items():
            if row.get_child_visible():
                self.choose(name)
                return

    def _command(self, name: str) -> None:
        self.popdown()
        self._run(name)

    def _mode(self, kind: MarkerKind) -> None:
        self.popdown()
        self._pick(kind)

    def _opened(self) -> None:
        self.search.set_text("")
        self.search.grab_focus()

    # -- model -------------------------------------------------------------------------------
    def _on_connection(self, _old: ConnectionState, new: ConnectionState) -> None:
        self.set_visible(new.phase is Phase.CONNECTED and any(n in new.offers for n in NAV_OFFERS))
        self._update_buttons()

    def _on_nav(self, old: NavState, new: NavState) -> None:
        if new.goals != self._goals:
            self._fill(new.goals)
        current = new.target if new.navigating else ""
        if current != self._current:
            for name in (self._current, current):
                row = self.rows.get(name)
                if row is not None:
                    (row.add_css_class if name == current else row.remove_css_class)("current-goal")
            self._current = current

    def _fill(self, goals: tuple[str, ...]) -> None:
        self._goals = goals
        for old in self.rows.values():  # ListBox.remove_all is GTK 4.12; Debian 12 has 4.8
            self.list.remove(old)
        self.rows = {}
        for name in goals:
            row = Gtk.ListBoxRow()
            row.goal = name  # type: ignore[attr-defined]
            label = Gtk.Label(label=name, xalign=0.0)
            label.set_use_markup(False)
            label.set_ellipsize(Pango.EllipsizeMode.END)
            row.set_child(label)
            row.set_tooltip_text(
                _("Drive to {name} (the robot drives by itself; STOP ends it)").format(name=name)
            )
            accessible.name(row, name)  # GTK 4.8 names no row by its label: it would be read as nothing
            self.list.append(row)
            self.rows[name] = row
        self.empty.set_visible(not goals)

    def _filter(self) -> None:
        self.list.invalidate_filter()
        shown = any(_matches(self.search.get_text(), n) for n in self.rows)
        self.empty.set_text(_("No goal matches") if self.rows else _("This map has no goals"))
        self.empty.set_visible(not shown)

    def commands_changed(self, states: Mapping[str, CommandState]) -> None:
        """The registry's states (the window forwards them): Home, Dock, Tour follow theirs."""
        if any(name in states for name in COMMANDS_SHOWN):
            self._states.update({n: s for n, s in states.items() if n in COMMANDS_SHOWN})
            self._update_buttons()

    def _update_buttons(self) -> None:
        conn = self.model.connection.value
        connected = conn.phase is Phase.CONNECTED
        why: list[str] = []
        for name in COMMANDS_SHOWN:
            state = self._states.get(name)
            enabled = state is not None and state.enabled
            reason = (
                ""
                if enabled
                else _short(reason_words(state.reason) if state is not None else _("not connected"))
            )
            self._set(name, enabled, reason, why)
        for kind, label, data, _tip in MODES:
            offered = connected and data in conn.offers
            reason = "" if offered else _(NOT_OFFERED) if connected else _("not connected")
            self._set(kind.value, offered, reason, why, _(label).rstrip("…"))
        self.reasons.set_text("\n".join(why))
        self.reasons.set_visible(bool(why))

    def _set(self, name: str, enabled: bool, reason: str, why: list[str], label: str = "") -> None:
        button = self.buttons[name]
        button.set_sensitive(enabled)
        label = label or button.get_label() or name
        if enabled:
            button.set_tooltip_text(self._tips[name])
        else:
            why.append(f"{label}: {reason}")
            button.set_tooltip_text(f"{label}: {reason}")


def _short(reason: str) -> str:
    if reason.startswith(("this server does not offer", "this server offers no")):
        return _(NOT_OFFERED)
    return reason or "unavailable"

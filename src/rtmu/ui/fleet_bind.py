"""The fleet in the window: the robot list, every robot on the map, the selection the window shows.

Wiring only (the window composes it; it owns no socket and no robot). It

* puts the :class:`~rtmu.ui.robot_list.RobotList` beside the map (under it on a narrow
  window) — shown only while the fleet lists more than one robot, so a one-robot profile
  looks exactly as before. It lists every robot the roster names (those not connected
  say so; a click connects one: ``Fleet.select_named``), and follows a roster that names
  hundreds of robots at most every :data:`LIST_SYNC_MS`, so the window keeps answering keys;
* gives each robot a colour for its life in the fleet and hands the map stage the other
  robots that share the selected one's map (``fleet_draw``), redrawing when one moves;
* follows ``Fleet.selected``: the window shows the new robot (``MainWindow.show_session``);
  the fleet has already stopped the one shown before;
* gives the robots not shown a :class:`BackgroundView`: their warnings and a lost link come
  as a banner with their name; their command states are not the window's business.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from itertools import islice

import gi
import numpy as np

gi.require_version("Gtk", "4.0")
from gi.repository import GLib, Gtk  # noqa: E402

from ..base.i18n import _, ngettext  # noqa: E402
from ..base.notices import Kind, Level, Notice  # noqa: E402
from ..control.commands import CommandState  # noqa: E402
from ..fleet.sessions import Fleet, RobotSession  # noqa: E402
from ..model.observables import ConnectionState, LinkLevel, Phase  # noqa: E402
from ..settings.store import Profile  # noqa: E402
from .fleet_draw import RGB, FleetMark, fleet_colour  # noqa: E402
from .mapview import STALE_AFTER  # noqa: E402
from .notice_router import say_stop  # noqa: E402
from .overlays import ROBOT_RGB  # noqa: E402
from .robot_list import NARROW_PX, RobotList  # noqa: E402
from .state_words import sentence_words  # noqa: E402
from .window import MainWindow  # noqa: E402

OTHER_TRAIL = 300
"""Trail points drawn for a robot not selected (its latest; the selected robot's whole trail is drawn)."""
OTHERS_REDRAW_MS = 66
"""At most ~15 redraws a second for the robots not selected (their status comes at 10 Hz each)."""
LINK_GRACE_MS = 1000
"""A robot's lost link is said this long after it happens (unless the whole roster went meanwhile)."""
LIST_SYNC_MS = 150
"""The robot list follows the roster's names at most this often (a central server may announce
thousands one by one: each is one cheap event, the list's rows are updated in one go)."""
REFRESH_MS = 300
"""How often rows re-read what changes without an event (a status growing old, the window's width)."""
QUIET_KINDS = (Kind.CONNECTION, Kind.LINK, Kind.SPEED, Kind.SPEED_LIMIT)
"""Notices of a robot not shown that are not repeated as banners (its row shows its link)."""


class BackgroundView:
    """The controller's View for a robot the window does not show."""

    def __init__(self, window: MainWindow, name: str) -> None:
        self.window = window
        self.name = name

    def notify(self, notice: Notice) -> None:
        say_stop(notice, self.name)
        if notice.level is Level.INFO or notice.kind in QUIET_KINDS:
            return
        self.window.banners.tell(f"fleet:{self.name}", notice.level.value, f"{self.name}: {notice.text}",
                                 timeout=6.0)  # fmt: skip

    def commands_changed(self, states: Mapping[str, CommandState]) -> None:
        pass

    def ask_password(self, profile: Profile, answer: Callable[[str | None], None]) -> None:
        self.window.ask_password(profile, answer)

    def open_dialog(self, name: str) -> None:
        pass

    def driving(self) -> None:
        pass  # a robot in the background takes no keys


class FleetBinding:
    """See the module notes. ``close`` unhooks everything (the window's shutdown)."""

    def __init__(self, window: MainWindow, fleet: Fleet) -> None:
        self.window = window
        self.fleet = fleet
        self._colours: dict[int, RGB] = {}
        self._hooks: dict[int, list[Callable[[], None]]] = {}
        self._seen: dict[int, float | None] = {}
        self._trails: dict[int, tuple[object, np.ndarray]] = {}
        self._lost: dict[str, str] = {}
        """Robots not shown whose link is lost (name → reason), in the order they were lost."""
        self._lost_source = 0
        self.drawn_updates: dict[str, int] = {}
        """Per robot name: frames that showed a new status of it (the benchmark's on-screen rate)."""
        self.robot_list = RobotList(select=self._select_named, colour=self.colour, session_of=fleet.named)
        self.robot_list.set_visible(False)
        window.body.append(self.robot_list)
        window.stage.fleet = self.marks
        window.keyboard.fleet = fleet  # Alt+1…9, Alt+Page Down / Up and the menu's Robots submenu
        self._unobserve = [
            fleet.sessions.observe(lambda _old, _new: self._sessions_changed()),
            fleet.selected.observe(self._selected_changed),
            fleet.listed.observe(lambda _old, _new: self._queue_list()),
        ]
        self._list_source = 0
        self._narrow: bool | None = None
        self._stale_seen: tuple[bool, ...] = ()
        self._menu_names: tuple[str, ...] | None = None
        self._sessions_changed()
        self._sync_list()
        self._fit_width()
        self._redraw_source = 0
        self._timer = GLib.timeout_add(REFRESH_MS, self._refresh)

    def colour(self, session: RobotSession) -> RGB:
        """The robot's colour for as long as it is in the fleet (by order of arrival)."""
        key = id(session)
        if key not in self._colours:
            self._colours[key] = fleet_colour(len(self._colours))
        return self._colours[key]

    # -- the fleet's changes -------------------------------------------------------------------
    def _sessions_changed(self) -> None:
        sessions = self.fleet.sessions.value
        alive = {id(s) for s in sessions}
        for key in [k for k in self._hooks if k not in alive]:
            for unhook in self._hooks.pop(key):
                unhook()
            self._seen.pop(key, None)
            self._trails.pop(key, None)
        selected = self.fleet.selected.value
        for session in sessions:
            if id(session) in self._hooks:
                continue
            self.colour(session)
            self._hooks[id(session)] = self._hook(session)
            if session is not selected:
                session.attach_view(BackgroundView(self.window, session.name))
        self._queue_list()  # the list and the menu's Robots submenu: once for a burst of robots
        names = {s.name for s in sessions}
        if any(name not in names for name in self._lost):
            self._lost = {n: e for n, e in self._lost.items() if n in names}
            self._tell_lost()
        self.window.stage.queue_draw()

    def _hook(self, session: RobotSession) -> list[Callable[[], None]]:
        state = session.state

        def changed(_old: object, _new: object) -> None:
            self._robot_changed(session)

        def connection(old: ConnectionState, new: ConnectionState) -> None:
            self._connection_changed(session, old, new)

        return [
            state.robot.observe(changed),
            state.health.observe(changed),
            state.connection.observe(connection),
            state.trail.observe(lambda: self._robot_changed(session)),
        ]

    def _selected_changed(self, old: RobotSession | None, new: RobotSession | None) -> None:
        if new is None:
            return
        self.window.show_session(new)
        if self._lost.pop(new.name, None) is not None:  # the window's own link banner speaks for it now
            self._tell_lost()
        if old is not None and not old.closed:
            old.attach_view(BackgroundView(self.window, old.name))
        self.robot_list.show_selected(new.name)
        self.window.stage.queue_draw()

    def _robot_changed(self, session: RobotSession) -> None:
        # Rows are refreshed on the timer (``_refresh``): a status per robot every 100 ms must not
        # cost a row update each; the map shows poses at once.
        if session is not self.fleet.selected.value and not self._redraw_source:
            # The selected robot's own changes redraw through the window at once; the others' are
            # gathered into at most one redraw per OTHERS_REDRAW_MS (20 robots at 10 Hz would
            # otherwise ask for a frame every 5 ms; each frame shows every robot's latest status).
            self._redraw_source = GLib.timeout_add(OTHERS_REDRAW_MS, self._redraw_others)

    def _redraw_others(self) -> bool:
        self._redraw_source = 0
        self.window.stage.queue_draw()
        return False

    def _connection_changed(self, session: RobotSession, old: ConnectionState, new: ConnectionState) -> None:
        self._robot_changed(session)
        row = self.robot_list.row_of(session)  # its row alone: 50 robots connecting, not 50² row updates
        if row is not None:
            row.update()
        lost = old.phase is Phase.CONNECTED and new.phase in (Phase.RECONNECTING, Phase.FAILED)
        if lost and session is not self.fleet.selected.value and len(self.fleet) > 1:
            self._lost[session.name] = new.error
        elif new.phase is Phase.CONNECTED or session.closed:
            self._lost.pop(session.name, None)
        else:
            return
        self._tell_lost()

    def _tell_lost(self) -> None:
        """Say the lost links after ``LINK_GRACE_MS``, so a central server's end is said once, by the fleet.

        When the central server dies, every forwarded link drops with it; the roster's loss,
        arriving a moment later, closes those sessions and empties ``_lost`` before this speaks.
        """
        if not self._lost:
            self._tell_lost_now()
        elif not self._lost_source:
            self._lost_source = GLib.timeout_add(LINK_GRACE_MS, self._tell_lost_later)

    def _tell_lost_later(self) -> bool:
        self._lost_source = 0
        self._tell_lost_now()
        return False

    def _tell_lost_now(self) -> None:
        """ONE banner, updated in place, names the robots (not shown) whose link is lost."""
        if not self._lost:
            self.window.banners.dismiss("fleet:links")
            return
        if len(self._lost) == 1:
            name, error = next(iter(self._lost.items()))
            text = (
                _("{robot}: link lost ({error})").format(robot=name, error=sentence_words(error))
                if error
                else _("{robot}: link lost").format(robot=name)
            )
        else:
            text = ngettext(
                "{count} robot lost its link: {robots}",
                "{count} robots lost their link: {robots}",
                len(self._lost),
            ).format(count=len(self._lost), robots=", ".join(self._lost))
        self.window.banners.tell(
            "fleet:links", "warning", _("{what} — the other robots carry on").format(what=text), timeout=None
        )

    # -- the robot list --------------------------------------------------------------------------
    def _select_named(self, name: str) -> None:
        """A row was clicked: select that robot, connecting it if it is only listed."""
        try:
            self.fleet.select_named(name)
        except ValueError:  # it left the list meanwhile
            self._queue_list()

    def _queue_list(self) -> None:
        if not self._list_source:
            self._list_source = GLib.timeout_add(LIST_SYNC_MS, self._sync_list_later)

    def _sync_list_later(self) -> bool:
        self._list_source = 0
        self._sync_list()
        return False

    def _sync_list(self) -> None:
        """The list's rows: every listed robot, then any connected one the roster does not list."""
        listed = [e.name for e in self.fleet.listed.value]
        known = set(listed)
        names = listed + [s.name for s in self.fleet.sessions.value if s.name not in known]
        self.robot_list.set_names(names)
        selected = self.fleet.selected.value
        self.robot_list.show_selected(selected.name if selected is not None else None)
        self.robot_list.set_visible(len(names) > 1)
        connected = tuple(s.name for s in self.fleet.sessions.value)
        if connected != self._menu_names:  # rebuilding the menu costs GTK a rebuild per item: not per robot
            self._menu_names = connected
            self.window.keyboard.fleet_changed()

    def _refresh(self) -> bool:
        """Rows and markers of robots that went quiet (no event says so), and the window's width."""
        self.robot_list.refresh()
        self._fit_width()
        stale = tuple(self._stale(s) for s in self.fleet.sessions.value)
        if stale != self._stale_seen:
            self._stale_seen = stale
            self.window.stage.queue_draw()
        return True

    def _fit_width(self) -> None:
        width = self.window.get_width() or self.window.get_default_size()[0]
        narrow = 0 < width < NARROW_PX
        if narrow == self._narrow:
            return
        self._narrow = narrow
        self.window.body.set_orientation(Gtk.Orientation.VERTICAL if narrow else Gtk.Orientation.HORIZONTAL)
        self.robot_list.set_narrow(narrow)

    # -- the map -------------------------------------------------------------------------------
    def marks(self) -> tuple[Sequence[FleetMark], RGB]:
        """The other robots on the selected robot's map, and the selected robot's colour."""
        selected = self.fleet.selected.value
        sessions = self.fleet.sessions.value
        rgb = self.colour(selected) if selected is not None and len(sessions) > 1 else ROBOT_RGB
        shown_map = selected.state.map.value.name if selected is not None else None
        out = []
        for session in sessions:
            r = session.state.robot.value
            if r.numbers_at is not None and self._seen.get(id(session)) != r.numbers_at:
                self._seen[id(session)] = r.numbers_at
                self.drawn_updates[session.name] = self.drawn_updates.get(session.name, 0) + 1
            if session is selected or r.numbers_at is None or session.state.map.value.name != shown_map:
                continue
            trail = self._trail_array(session)
            out.append(FleetMark(r.x, r.y, r.th, self.colour(session), self._stale(session), trail))
        return out, rgb

    def _trail_array(self, session: RobotSession) -> np.ndarray:
        """The robot's latest trail points as an (n, 2) array, rebuilt only when the trail changed."""
        points = session.state.trail.points
        key = (len(points), points[-1] if points else None)
        cached = self._trails.get(id(session))
        if cached is not None and cached[0] == key:
            return cached[1]
        tail = islice(points, max(0, len(points) - OTHER_TRAIL), None)
        array = np.array(list(tail), dtype=float).reshape(-1, 2)
        self._trails[id(session)] = (key, array)
        return array

    @staticmethod
    def _stale(session: RobotSession) -> bool:
        state = session.state
        if (
            state.connection.value.phase is not Phase.CONNECTED
            or state.health.value.level is not LinkLevel.OK
        ):
            return True
        age = session.runner.status_age()
        return age is None or age > STALE_AFTER

    def close(self) -> None:
        if self._lost_source:
            GLib.source_remove(self._lost_source)
            self._lost_source = 0
        if self._redraw_source:
            GLib.source_remove(self._redraw_source)
            self._redraw_source = 0
        if self._list_source:
            GLib.source_remove(self._list_source)
            self._list_source = 0
        if self._timer:
            GLib.source_remove(self._timer)
            self._timer = 0
        for unhook in self._unobserve:
            unhook()
        self._unobserve = []
        for hooks in self._hooks.values():
            for unhook in hooks:
                unhook()
        self._hooks = {}
        self.window.stage.fleet = None

"""One session per robot, and the fleet that owns them: what the application builds.

A :class:`RobotSession` puts together everything that belongs to one robot —
its state (:class:`~rtmu.model.observables.RobotModel`: robot, map, camera, connection,
health, trail), its network thread (:class:`~rtmu.client.runner.ClientRunner`,
which holds the drive lease, the session and its guardian) and its
:class:`~rtmu.control.controller.Controller` — and takes them apart again in one
:meth:`RobotSession.close` that stops the robot first.

The :class:`Fleet` owns the sessions, says which one is selected, and stops
them all at once: the application's close, quit, suspend and signal paths go
through :meth:`Fleet.stop_all` / :meth:`Fleet.close`, so no robot is left
driving because a window only knew about another one. A fleet follows a
:class:`~rtmu.client.roster.Roster` (:meth:`Fleet.follow`): every robot it names is
*listed*; the first ``connect_at_most`` get a session each, which connects (the
others are connected on demand when selected: :mod:`.budget`); a robot removed has its
session closed (stopped first); a lost roster stops every robot and says so once.
Selecting a robot first stops the one selected before, so a held key never carries
over, and arms the window's ONE guardian (:class:`~rtmu.guardian.shared.SharedGuardian`)
for the new one: its controller refuses drive keys until it is armed. Closing a session
never blocks the UI thread (its network thread ends on a thread of its own); closing the
fleet closes them all at once, within one bounded wait.
GTK-free: ``post`` is ``GLib.idle_add`` in the app and a direct call or a
queue in tests; everything here runs on the UI thread.
"""

from __future__ import annotations

import concurrent.futures
import threading
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

from ..base.i18n import _
from ..base.notices import Kind, Level, Notice
from ..client.link import Opener, open_tcp
from ..client.roster import (
    DirectRoster,
    RobotAdded,
    RobotEndpoint,
    RobotRemoved,
    Roster,
    RosterEvent,
    RosterLost,
    RosterRestored,
)
from ..client.runner import ClientRunner, Post, call_directly, settle
from ..client.session import SessionConfig
from ..control.commands import COMMANDS, CommandRegistry
from ..control.controller import Controller
from ..control.ports import NoView, SecretStore, View
from ..guardian.shared import GuardianSeat, SharedGuardian
from ..model.observables import Observable, OperatorState, RobotModel
from ..recorder import Recorder, RecorderConfig
from ..recorder.files import recordings_dir
from ..settings.store import Profile, RecordingSettings
from .budget import CONNECT_AT_MOST, to_connect, to_let_go

CLOSE_TIMEOUT = 1.5
"""How long closing one session may take (stop, disconnect, end the network thread)."""
STOP_TIMEOUT = 0.5
"""How long :meth:`Fleet.stop_all` waits for every stop to leave the process."""


class RobotSession:
    """One robot: its state, network runner and controller. Use from the UI thread."""

    def __init__(
        self,
        operator: OperatorState,
        *,
        post: Post = call_directly,
        config: SessionConfig | None = None,
        profile: Profile | None = None,
        secrets: SecretStore | None = None,
        clock: Callable[[], float] = time.monotonic,
        registry: CommandRegistry = COMMANDS,
        recording: RecordingSettings | None = None,
        opener: Opener | None = None,
        guardian: SharedGuardian | None = None,
    ) -> None:
        self.state = RobotModel()
        self.seat: GuardianSeat | None = None
        """This robot's seat at the window's one guardian (None: none, or its own per connection)."""
        if guardian is not None:
            p = profile or Profile()
            self.seat = guardian.seat(p.name or f"{p.host}:{p.port}")
            config = replace(config or SessionConfig(), guardian=False, guardian_seat=self.seat)
        self.recorder = recorder_for(recording)
        """This robot's flight recorder (None when recording is off: the default outside the window)."""
        if self.recorder is not None:  # ``opener``: where the links come from (a replay's recording)
            opener = self.recorder.opener(opener or open_tcp)
        self.runner = ClientRunner(self.state, post=post, clock=clock, config=config, opener=opener)
        self.controller = Controller(
            self.state,
            operator,
            self.runner,
            NoView(),
            clock=clock,
            registry=registry,
            secrets=secrets,
            profile=profile,
        )
        if self.recorder is not None:  # every source of the recording; the controller's guard for intents
            self.recorder.attach(self.runner)
            self.controller.tap = self.recorder.intent
        if self.seat is not None:  # no drive key before the guardian is armed for this robot
            self.controller.drive_gate = self.seat.waiting_reason
        self.closed = False

    @property
    def name(self) -> str:
        """The profile's name, else ``host:port`` (what a robot list shows)."""
        p = self.controller.profile
        return p.name or f"{p.host}:{p.port}"

    def start(self) -> RobotSession:
        """Start the network thread."""
        self.runner.start()
        return self

    def attach_view(self, view: View) -> None:
        """Let ``view`` (a window) hear this robot's notices and command states."""
        self.controller.view = view
        view.commands_changed(self.controller.command_states())

    def stop(self) -> concurrent.futures.Future[bool]:
        """End any held drive and send zero ratios + ``stop`` now; the Future says if it left in time."""
        self.controller.stop()
        return self.runner.stop_flushing(STOP_TIMEOUT)

    def close(self, timeout: float = CLOSE_TIMEOUT, *, stop: bool = True) -> None:
        """Stop the robot, then unhook every observer and end the network thread. Idempotent."""
        if self.begin_close(stop=stop):
            self.finish_close(timeout)

    def begin_close(self, *, stop: bool = True) -> bool:
        """The UI thread's part of :meth:`close`: stop the robot (unless ``stop`` is False: an idle
        robot let go of), unhook the controller. False if it was closed already."""
        if self.closed:
            return False
        self.closed = True
        if stop:
            self.controller.stop()
        self.controller.close()
        return True

    def finish_close(self, timeout: float = CLOSE_TIMEOUT) -> None:
        """The rest of :meth:`close` — end the network thread, finish the recording — from any thread."""
        self.runner.close(timeout)
        if self.recorder is not None:
            self.recorder.close(timeout)


def recorder_for(settings: RecordingSettings | None) -> Recorder | None:
    """A recorder as ``settings`` say (None: off). The window passes its settings; tests and scripts none."""
    if settings is None or not settings.enabled:
        return None
    directory = Path(settings.directory) if settings.directory else recordings_dir()
    config = RecorderConfig(
        directory, max_bytes=settings.max_file_mb * 1_000_000, keep_days=settings.keep_days
    )
    return Recorder(config)


def robot_profile(base: Profile, endpoint: RobotEndpoint) -> Profile:
    """The profile one robot of a fleet connects with: ``base``'s user and choices, its own address."""
    return replace(base, name=endpoint.name, host=endpoint.host, port=endpoint.port, robots=(), central="")


def direct_roster(profile: Profile) -> DirectRoster | None:
    """The roster of a profile that lists its robots (None: one robot, or a central server's)."""
    if not profile.robots:
        return None
    return DirectRoster([RobotEndpoint(r.name, r.host, r.port) for r in profile.robots])


SessionMaker = Callable[[RobotEndpoint], RobotSession]
"""Builds (not starts) the session of one robot a roster announced."""
Announce = Callable[[str], None]
"""Tells the operator one sentence (a window banner; a list in tests)."""


class Fleet:
    """The robot sessions of one application, the selected one, and :meth:`stop_all`.

    ``listed`` (every robot the roster names), ``sessions`` (those connected) and ``selected`` are
    observables, so a robot list binds to them. ``guardian``: the window's one guardian, armed for
    the selected robot (None: none, or each session its own). The fleet ends it in :meth:`close`.
    """

    def __init__(
        self,
        operator: OperatorState | None = None,
        *,
        connect_at_most: int = CONNECT_AT_MOST,
        guardian: SharedGuardian | None = None,
    ) -> None:
        self.operator = operator or OperatorState()
        self.listed: Observable[tuple[RobotEndpoint, ...]] = Observable(())
        """Every robot the roster names now, in its order (connected or not)."""
        self.sessions: Observable[tuple[RobotSession, ...]] = Observable(())
        self.selected: Observable[RobotSession | None] = Observable(None)
        self.connect_at_most = max(1, connect_at_most)
        """How many robots are connected at once (the others are connected when selected)."""
        self.guardian = guardian
        self._roster: Roster | None = None
        self._make: SessionMaker | None = None
        self._announce: Announce = lambda _text: None
        self._used: dict[int, float] = {}
        """When each session was last selected (the least recently used one is let go first)."""
        self._closing: list[threading.Thread] = []
        self.roster_lost: str | None = None
        """Why the roster went away (None while it is there): said once, every robot stopped."""
        self.selected.observe(self._selection_moved)
        self.sessions.observe(lambda _old, _new: self._expect())

    # -- the roster ------------------------------------------------------------------------------
    def follow(self, roster: Roster, make: SessionMaker, announce: Announce | None = None) -> None:
        """List every robot ``roster`` announces; build (``make``), start and connect a session for the
        first ``connect_at_most`` of them.

        Call once, on the UI thread; the roster must deliver its events on this thread too
        (its ``post``). The first robot becomes the selection; later ones do not take it.
        """
        if self._roster is not None:
            raise RuntimeError("this fleet already follows a roster")
        self._roster, self._make = roster, make
        if announce is not None:
            self._announce = announce
        roster.start(self.on_roster)

    def on_roster(self, event: RosterEvent) -> None:
        """One roster event (see :mod:`rtmu.client.roster`)."""
        match event:
            case RobotAdded(endpoint):
                self._robot_added(endpoint)
            case RobotRemoved(name, reason):
                self._robot_removed(name, reason)
            case RosterLost(reason, retrying):
                self._roster_lost(reason, retrying)
            case RosterRestored():
                self._roster_restored()

    def _robot_added(self, endpoint: RobotEndpoint) -> None:
        if self._make is None or self.roster_lost is not None:
            return
        listed = self.listed.value
        if any(e.name == endpoint.name for e in listed):  # announced again: in its place, as new
            self.listed.set(tuple(endpoint if e.name == endpoint.name else e for e in listed))
        else:
            self.listed.set((*listed, endpoint))
        old = self.named(endpoint.name)
        if old is not None:  # a central server's robot came back: a fresh session
            self.remove(old)
        if old is not None or len(self.sessions.value) < self.connect_at_most:
            self._connect(endpoint)

    def _robot_removed(self, name: str, reason: str) -> None:
        self.listed.set(tuple(e for e in self.listed.value if e.name != name))
        session = self.named(name)
        if session is not None:
            self.remove(session)
            self._announce(f"{name} left the fleet" + (f": {reason}" if reason else ""))
            self._fill()

    def _roster_lost(self, reason: str, retrying: bool = False) -> None:
        """Every robot of the roster is gone: stop them all at once, say it ONCE, then close them."""
        if self.roster_lost is not None:
            return
        self.roster_lost = reason
        self.stop_all()
        sessions = self.sessions.value
        for session in sessions:
            session.controller.view = NoView()  # their own link-lost notices would repeat this one
        again = "; trying to reach it again" if retrying else ""
        self._announce(f"Lost the robot list ({reason}): every robot was told to stop{again}")
        for session in sessions:
            self._close_soon(session)
        self.sessions.set(())
        self.selected.set(None)
        self.listed.set(())

    def _roster_restored(self) -> None:
        """The roster's source is back: its robots come again as new sessions (none drives unpressed)."""
        if self.roster_lost is None:
            return
        self.roster_lost = None
        self._announce("The robot list is back: reconnecting to its robots (press again to drive)")

    def named(self, name: str) -> RobotSession | None:
        """The session of the robot called ``name`` (its profile's name), if any."""
        return next((s for s in self.sessions.value if s.name == name), None)

    def __iter__(self) -> Any:
        return iter(self.sessions.value)

    def __len__(self) -> int:
        return len(self.sessions.value)

    # -- connected on demand, within the budget -------------------------------------------------
    def _connect(self, endpoint: RobotEndpoint) -> RobotSession:
        assert self._make is not None
        session = self._make(endpoint).start()
        self.add(session, select=self.selected.value is None)
        session.controller.connect()
        return session

    def select_named(self, name: str) -> RobotSession:
        """Select the robot called ``name``: connected now if it is only listed (and the connected
        robot used least recently let go, beyond :attr:`connect_at_most`). ValueError if not listed."""
        session = self.named(name)
        if session is None:
            endpoint = next((e for e in self.listed.value if e.name == name), None)
            if endpoint is None or self._make is None:
                raise ValueError(f"no robot called {name!r} is listed")
            session = self._connect(endpoint)
        self.select(session)
        self._trim()
        return session

    def _fill(self) -> None:
        """Connect listed robots until :attr:`connect_at_most` are (after one left)."""
        if self._make is None or self.roster_lost is not None:
            return
        connected = [s.name for s in self.sessions.value]
        for name in to_connect([e.name for e in self.listed.value], connected, self.connect_at_most):
            endpoint = next(e for e in self.listed.value if e.name == name)
            self._connect(endpoint)

    def _trim(self) -> None:
        """Let go of the least recently used idle robots beyond :attr:`connect_at_most`."""
        for session in to_let_go(self.sessions.value, self.connect_at_most, keep=self._keeps,
                                 last_used=lambda s: self._used.get(id(s), 0.0)):  # fmt: skip
            self._close_soon(session, stop=False)
            self._forget(session)

    def _keeps(self, session: RobotSession) -> bool:
        c = session.controller
        return session is self.selected.value or c.navigating or bool(c.held) or c.analog_active

    # -- sessions ------------------------------------------------------------------------------
    def open(self, *, select: bool = True, **options: Any) -> RobotSession:
        """A new started session (``options`` as for :class:`RobotSession`), added to the fleet."""
        session = RobotSession(self.operator, **options).start()
        self.add(session, select=select)
        return session

    def add(self, session: RobotSession, *, select: bool = True) -> None:
        self.sessions.set((*self.sessions.value, session))
        if select or self.selected.value is None:
            self.selected.set(session)

    def select(self, session: RobotSession) -> None:
        """Make ``session`` the one that takes the drive keys, D-pad and navigation commands.

        The robot selected before is stopped first: its drive lease ends and it is sent a stop, and
        its held keys stay blocked, so nothing held carries over — the new robot moves only on a
        fresh press, once the guardian is armed for it. A navigation the server runs on it goes on
        (the operator did not ask to stop that; STOP on that robot still ends it).
        """
        if session not in self.sessions.value:
            raise ValueError("that session is not in this fleet")
        old = self.selected.value
        if old is session:
            return
        if old is not None and not old.closed and (old.controller.held or not old.controller.navigating):
            driving = bool(old.controller.held) or old.controller.analog_active
            old.controller.stop()  # also blocks its held keys until they are released
            if driving:  # a stop the operator did not press is said, with what to do
                said = _("Stopped {robot}: {selected} is selected now. Press again to drive it.").format(
                    robot=old.name, selected=session.name
                )
                old.controller.view.notify(Notice.stopped(Kind.SAFETY, said, Level.INFO))
        self.selected.set(session)

    def _selection_moved(self, _old: RobotSession | None, new: RobotSession | None) -> None:
        if new is not None:
            self._used[id(new)] = time.monotonic()
        if self.guardian is not None:
            self.guardian.choose(new.seat if new is not None else None)
        self._expect()

    def _expect(self) -> None:
        """Name the robots beside the selected one in the fleet's list — the likely next selections
        (Up and Down in the robot list) — to the guardian, which keeps its logins to them ready."""
        if self.guardian is None:
            return
        sessions, session = list(self.sessions.value), self.selected.value
        i = sessions.index(session) if session in sessions else -1
        beside = [sessions[j].seat for j in (i + 1, i - 1) if i >= 0 and 0 <= j < len(sessions)]
        self.guardian.expect(beside)

    def remove(self, session: RobotSession) -> None:
        """Close ``session`` (its robot is stopped first) and forget it."""
        self._close_soon(session)
        self._forget(session)

    def _forget(self, session: RobotSession) -> None:
        self._used.pop(id(session), None)
        remaining = tuple(s for s in self.sessions.value if s is not session)
        self.sessions.set(remaining)
        if self.selected.value is session:
            self.selected.set(remaining[0] if remaining else None)

    def _close_soon(self, session: RobotSession, *, stop: bool = True) -> None:
        """Stop (unless ``stop`` is False) and unhook now; end its thread off the UI thread."""
        if not session.begin_close(stop=stop):
            return
        self._closing = [t for t in self._closing if t.is_alive()]
        thread = threading.Thread(target=session.finish_close, name="rtmu-session-close", daemon=True)
        thread.start()
        self._closing.append(thread)

    def stop_all(self, wait: float | None = None) -> bool:
        """Stop every robot now (all stops are sent before any is waited for).

        With ``wait``: block up to that many seconds until every stop has left this process
        (for Ctrl+Z, which freezes us next); True when all did.
        """
        futures = [session.stop() for session in self.sessions.value]
        if wait is None:
            return True
        deadline = time.monotonic() + wait
        return all([settle(f, max(0.0, deadline - time.monotonic())) for f in futures])

    def close(self, timeout: float = CLOSE_TIMEOUT) -> None:
        """Stop every robot at once, then close every session together — one bounded wait of about
        ``timeout`` s for them all — and end the guardian. Idempotent."""
        if self._roster is not None:
            self._roster.close()
        self.stop_all()
        for session in self.sessions.value:
            self._close_soon(session)
        deadline = time.monotonic() + timeout + 0.5
        for thread in self._closing:
            thread.join(max(0.0, deadline - time.monotonic()))
        self._closing = [t for t in self._closing if t.is_alive()]
        self.sessions.set(())
        self.selected.set(None)
        if self.guardian is not None:
            self.guardian.close()

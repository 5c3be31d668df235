"""The operator's side of ARIA's central server: which robots it forwards, and where.

:func:`list_robots` asks once (``clientList``; used by ``rtmu fleet`` and ``--robot NAME``).
:class:`CentralRoster` is a :class:`~rtmu.client.roster.Roster` that stays logged in on a thread of its
own: the list first, then the ``clientAdded`` / ``clientRemoved`` broadcasts, each turned into a
:class:`RobotAdded` / :class:`RobotRemoved`; when the central server's connection ends (or never came
up), one :class:`RosterLost`. It then tries again (backing off to :data:`RETRY_MAX` s) unless
the failure cannot heal by itself (a refused login, a server that breaks the protocol); once back,
one :class:`RosterRestored` and the robots again, as new ones — none drives until pressed.
Every robot is reached on the central server's host at its forwarded port: ARIA's central server
always sends an empty hostname, and one that named another host would be sending the operator's
login (and drive commands) elsewhere, so such a name is not followed.

The central server is trusted no more than a robot: at most :data:`MAX_ROBOTS` robots are held, names
longer than :data:`MAX_NAME` or entries without a port are dropped (and counted), and names are kept as
plain text — whoever shows them escapes them. Names are compared as ARIA's central server compares
them, without case (:func:`robot_key`): ``ROBOT``, ``robot`` and ``Robot`` are one robot, and the one
listed or announced last takes the place of the others, as a robot switching again under its name
replaces its old connection there. ``--robot NAME`` that fits more than one listed entry is refused
with the candidates (:func:`find_robot`), never settled by a guess.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import threading
from collections.abc import Callable
from typing import Any

from ..protocol.payloads.central import CentralEntry, ClientAdded, ClientList, ClientRemoved
from ..values.target import Target
from .call_values import Packet
from .connection import AriaClient
from .defaults import CONNECT_TIMEOUT, DEFAULT_PORT
from .errors import ClientError
from .reconnect import Backoff, worth_retrying
from .roles import Role
from .roster import Emit, RobotAdded, RobotEndpoint, RobotRemoved, RosterEvent, RosterLost, RosterRestored

log = logging.getLogger("rtmu.central")

MAX_ROBOTS = 1000
"""Robots one roster holds; more are dropped (a fleet this big is not one operator's)."""
MAX_NAME = 512
"""ARIA's central server keeps a robot's name in 512 bytes; a longer one is not a robot's."""
CLOSE_JOIN_TIMEOUT = 2.0
RETRY_FIRST = 1.0
"""Seconds before the first new try after the central server was lost."""
RETRY_MAX = 30.0
"""Longest wait between tries (an operator waiting for a restarted central server waits at most this)."""

Listed = list[tuple[RobotEndpoint, CentralEntry]]
"""What :func:`list_robots` answers: each usable entry with the address it is reached at."""
Post = Callable[..., Any]
"""``post(fn, *args)``: run ``fn(*args)`` on the consumer's thread (``GLib.idle_add``, or a direct call)."""


def _direct(fn: Callable[..., Any], *args: Any) -> None:
    fn(*args)


def robot_key(name: str) -> str:
    """What makes two robot names the same robot: ARIA's central server compares them case-blind."""
    return name.casefold()


class AmbiguousRobot(ValueError):
    """``--robot NAME`` fits more than one listed entry; the sentence names them."""


def find_robot(robots: Listed, wanted: str) -> RobotEndpoint | None:
    """The one listed robot named ``wanted`` (without case, as ARIA compares); None when none is;
    :class:`AmbiguousRobot` when several entries are (a central server that broke its own rule)."""
    found = [e for e, _ in robots if robot_key(e.name) == robot_key(wanted)]
    if len(found) > 1:
        listed = ", ".join(f"'{e.name}' (port {e.port})" for e in found)  # plain: shown through visible()
        raise AmbiguousRobot(
            f"'{wanted}' is ambiguous: the central server lists {len(found)} robots of that name, which "
            f"ARIA counts as one ({listed}); it should list one"
        )
    return found[0] if found else None


def one_per_name(
    robots: list[tuple[RobotEndpoint, CentralEntry]],
) -> list[tuple[RobotEndpoint, CentralEntry]]:
    """One entry per robot as ARIA compares names: the one listed last, in the place of the first."""
    out: dict[str, tuple[RobotEndpoint, CentralEntry]] = {}
    for item in robots:
        key = robot_key(item[0].name)
        out[key] = item
    return list(out.values())


def endpoint_of(entry: CentralEntry, central_host: str, central_port: int) -> RobotEndpoint | None:
    """The address an operator reaches ``entry`` at; None for an entry no robot could have sent."""
    if not entry.name or len(entry.name) > MAX_NAME or not 0 < entry.port <= 0xFFFF:
        return None
    return RobotEndpoint(entry.name, central_host, entry.port, via=f"{central_host}:{central_port}")


async def list_robots(
    host: str,
    port: int = DEFAULT_PORT,
    user: str = "",
    password: str = "",
    *,
    timeout: float = CONNECT_TIMEOUT,
    protocol: str | None = None,
) -> Listed:
    """Log in to the central server, read ``clientList`` once, log out: every usable entry, in order
    (:func:`one_per_name` makes it one per robot; :func:`find_robot` finds one).

    Raises :class:`~rtmu.client.errors.ClientError` (``NotSupported`` when the server is not a central
    server) or a ``ProtocolError`` for a list that does not decode.
    """
    client = AriaClient()
    try:
        target = Target(host, port, user, password, protocol=protocol)
        await client.connect(target, timeout=timeout, role=Role.OBSERVER)
        reply = await client.request_once(ClientList.DATA_NAME, timeout=timeout)
        listed = ClientList.decode(reply.payload)
    finally:
        await client.disconnect()
    out: Listed = []
    seen: set[tuple[str, int]] = set()
    for entry in listed.entries[:MAX_ROBOTS]:
        endpoint = endpoint_of(entry, host, port)
        if endpoint is not None and (endpoint.name, endpoint.port) not in seen:
            seen.add((endpoint.name, endpoint.port))
            out.append((endpoint, entry))
    return out


class CentralRoster:
    """The robots behind one central server, kept up to date on a network thread of its own."""

    def __init__(
        self,
        host: str,
        port: int = DEFAULT_PORT,
        *,
        user: str = "",
        password: str = "",
        post: Post = _direct,
        timeout: float = CONNECT_TIMEOUT,
        max_robots: int = MAX_ROBOTS,
    ) -> None:
        self.host = host
        self.port = port
        self._user = user
        self._password = password
        self._post = post
        self.timeout = timeout
        self.max_robots = max_robots
        self.robots: dict[str, RobotEndpoint] = {}
        """Robots known now, by :func:`robot_key` of their name (touched on the roster's thread only)."""
        self.dropped = 0
        """Entries refused: malformed, over :data:`MAX_ROBOTS`, or broadcasts that did not decode."""
        self._emit: Emit | None = None
        self._closed = threading.Event()
        self._lost_sent = False
        self.backoff = Backoff(initial=RETRY_FIRST, maximum=RETRY_MAX)
        self.attempts = 0
        """Connections tried so far (the first included)."""
        self._thread: threading.Thread | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._task: asyncio.Task[None] | None = None

    @property
    def given_up(self) -> bool:
        """True once the roster has stopped for good by itself (a loss that cannot heal, e.g. a refused
        login): its thread has ended without :meth:`close`. Tests wait for this instead of sleeping past
        a retry that must not come."""
        thread = self._thread
        return thread is not None and not thread.is_alive() and not self._closed.is_set()

    # -- Roster ---------------------------------------------------------------------------
    def start(self, emit: Emit) -> None:
        if self._thread is not None:
            raise RuntimeError("a CentralRoster starts once")
        self._emit = emit
        self._thread = threading.Thread(target=self._main, name="rtmu-central", daemon=True)
        self._thread.start()

    def close(self) -> None:
        """Log out and end the thread; nothing is emitted after this returns."""
        self._closed.set()
        loop, task = self._loop, self._task
        if loop is not None and task is not None:
            with contextlib.suppress(RuntimeError):  # the loop already ended
                loop.call_soon_threadsafe(task.cancel)
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(CLOSE_JOIN_TIMEOUT)

    # -- the thread -------------------------------------------------------------------------
    def _main(self) -> None:
        loop = asyncio.new_event_loop()
        self._loop = loop
        try:
            self._task = loop.create_task(self._run())
            if self._closed.is_set():
                self._task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                loop.run_until_complete(self._task)
        finally:
            loop.close()

    def _deliver(self, event: RosterEvent) -> None:
        if self._closed.is_set() or self._emit is None:
            return
        self._post(self._emit_if_open, event)

    def _emit_if_open(self, event: RosterEvent) -> None:
        if not self._closed.is_set() and self._emit is not None:
            self._emit(event)

    def _lost(self, reason: str, retrying: bool) -> None:
        if self._lost_sent:
            return
        self._lost_sent = True
        self.robots.clear()
        self._deliver(RosterLost(reason, retrying))

    async def _run(self) -> None:
        """Stay logged in; after a loss, try again until closed or the failure cannot heal."""
        with contextlib.suppress(asyncio.CancelledError):
            while not self._closed.is_set():
                reason, retry = await self._serve_once()
                self._lost(reason, retry)
                if not retry:
                    return
                await asyncio.sleep(self.backoff.next_delay())

    async def _serve_once(self) -> tuple[str, bool]:
        """One login: the list, then broadcasts until the link ends. (why it ended, worth retrying)."""
        closed: asyncio.Future[ClientError] = asyncio.get_running_loop().create_future()

        def on_close(error: ClientError) -> None:
            if not closed.done():
                closed.set_result(error)

        self.attempts += 1
        client = AriaClient(on_close=on_close)
        try:
            # The password stays while the roster lives: a lost central server is logged in to again.
            target = Target(self.host, self.port, self._user, self._password)
            await client.connect(target, timeout=self.timeout, role=Role.OBSERVER)
            self.backoff.reset()
            if self._lost_sent:  # before any robot: a broadcast may come ahead of the list
                self._lost_sent = False
                self._deliver(RosterRestored())
            client.request(ClientAdded.DATA_NAME, -1, self._on_added)
            client.request(ClientRemoved.DATA_NAME, -1, self._on_removed)
            reply = await client.request_once(ClientList.DATA_NAME, timeout=self.timeout)
            for entry in ClientList.decode(reply.payload).entries:
                self._add(entry)
            error = await closed
            return str(error), worth_retrying(error)
        except ClientError as exc:
            return str(exc) or type(exc).__name__, worth_retrying(exc)
        except Exception as exc:  # a ProtocolError in the list: the same server will send it again
            return str(exc) or type(exc).__name__, False
        finally:
            with contextlib.suppress(Exception):
                await client.disconnect()

    def _on_added(self, packet: Packet) -> None:
        try:
            entry = ClientAdded.decode(packet.payload).entry
        except Exception:
            self.dropped += 1
            return
        self._add(entry)

    def _on_removed(self, packet: Packet) -> None:
        try:
            entry = ClientRemoved.decode(packet.payload).entry
        except Exception:
            self.dropped += 1
            return
        key = robot_key(entry.name)
        known = self.robots.get(key)
        # Only the robot of that name and port: one replaced by a namesake has gone already.
        if known is not None and known.name == entry.name and known.port == entry.port:
            del self.robots[key]
            self._deliver(RobotRemoved(known.name, "left the central server"))

    def _add(self, entry: CentralEntry) -> None:
        endpoint = endpoint_of(entry, self.host, self.port)
        if endpoint is None:
            self.dropped += 1
            return
        key = robot_key(endpoint.name)
        old = self.robots.get(key)
        if old == endpoint:
            return  # heard in the list and in a broadcast
        if old is None and len(self.robots) >= self.max_robots:
            self.dropped += 1
            return
        if old is not None:  # ARIA's rule: a robot of the same name (any case) takes the old one's place
            why = "reconnected to the central server"
            if old.name != endpoint.name:
                why = f"replaced by {endpoint.name!r}, the same robot as ARIA compares names"
            self._deliver(RobotRemoved(old.name, why))
        self.robots[key] = endpoint
        self._deliver(RobotAdded(endpoint))

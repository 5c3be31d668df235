"""One operator session on the network loop: the connection's life, and the feeds that do the rest.

The :class:`Session` lives entirely on the network thread's asyncio loop (see ``runner`` for the
thread and the UI-facing facade). It connects, reconnects and disconnects; it is the one
:class:`~rtmu.client.feed.FeedContext` of its feeds — status, navigation, the map, popups, the
camera head, video, drawings, configuration, the server's commands and the drive loop — whose
subscriptions it makes on every connection, and it hands each operator intent
(:mod:`rtmu.values.intents`) to the feed that handles its type (:meth:`Session.dispatch`). Before
any intent that moves the robot, a held drive ends (its stop goes out first). It keeps a *shadow*
of the published state and hands a typed change (:data:`rtmu.values.state.StateChange`) to
``publish`` only when the value really changed, so an unchanged 10 Hz status costs the UI thread
nothing. Messages for the operator leave as typed :class:`rtmu.base.notices.Notice`.
"""

from __future__ import annotations

import asyncio
import logging
import time
from collections.abc import Callable, Coroutine
from dataclasses import replace
from typing import Any, TypeVar

from ..base.i18n import _
from ..base.notices import Kind, Notice
from ..guardian.shared import GuardianSeat
from ..protocol.errors import ProtocolError
from ..protocol.payloads import Side, decode_payload
from ..values.intents import Intent, Stop
from ..values.state import (
    ConnectionChanged,
    ConnectionState,
    MapModel,
    Phase,
    RobotChanged,
    RobotState,
    StateChange,
)
from ..values.target import Target
from .connection import AriaClient
from .diagnosis import explain
from .drive_loop import STEP_TIMEOUT, DriveFeed
from .errors import ClientError, NotSupported, ServerClosed
from .feed import Feed
from .feeds import FEEDS
from .lazy_feed import DeferredFeed
from .lease import DriveLease, EndReason
from .map_feed import MapFeed
from .reconnect import worth_retrying
from .session_config import SessionConfig
from .status_feed import StatusFeed
from .subscriptions import Handler, Subscription, applicable, merged

log = logging.getLogger(__name__)

Publish = Callable[[StateChange], None]
"""``publish(change)``: a new whole value for one part of the robot's state."""
NoticeFn = Callable[[Notice], None]
"""``notice(notice)``: a message for the operator, typed by what it is about."""
ClientFactory = Callable[[Callable[[ClientError], None]], AriaClient]
"""``factory(on_close)`` → a fresh, unconnected :class:`AriaClient` (its link is the factory's choice)."""
F = TypeVar("F", bound=Feed)

TASK_END_TIMEOUT = 0.5
"""How long closing waits for a cancelled task to finish before leaving it behind."""
READING_TIMES = frozenset({"numbers_at", "strings_at", "sonar_at", "laser_at"})
"""``RobotState``'s fields that say when a reading came (not compared): alone they change nothing shown."""
DECODE_CACHE_BYTES = 16384
"""Payloads up to this size are remembered with their value (a laser's 361 points take 2.9 kB);
bigger ones — pictures, map chunks — are always decoded and never kept."""


class Session:
    """See the module notes. Create on the loop; every method runs on the loop's thread."""

    def __init__(
        self,
        lease: DriveLease,
        publish: Publish,
        notice: NoticeFn | None = None,
        *,
        clock: Callable[[], float] = time.monotonic,
        config: SessionConfig | None = None,
        client_factory: ClientFactory | None = None,
    ) -> None:
        self.lease = lease
        self.publish_fn = publish
        self.notice_fn: NoticeFn = notice or (lambda notice: None)
        self.clock = clock
        self.config = config or SessionConfig()
        self.client_factory: ClientFactory = client_factory or (
            lambda on_close: AriaClient(on_close=on_close, clock=self.clock)
        )
        """Makes each connection's client: a replay or a test passes one over its own link."""
        self.client: AriaClient | None = None
        self._target: Target | None = None
        self._published: dict[type, StateChange] = {}
        self._robot = RobotState()
        self._times: dict[str, Any] = {}
        """Reading times (:data:`READING_TIMES`) newer than ``_robot``'s, kept until it is next built."""
        self._connection = ConnectionState()
        self._tasks: set[asyncio.Task[Any]] = set()
        self._reconnect_task: asyncio.Task[None] | None = None
        self._connecting: asyncio.Task[Any] | None = None
        self._subs: list[Subscription] = []
        """This connection's subscriptions (merged, where offered)."""
        self._held_subs: set[str] = set()
        """Conditional subscriptions (``only_while``) held now on this connection."""
        self._decoded: dict[str, tuple[bytes, Any]] = {}
        """Each data name's last small payload and its value: a stream that repeats itself (status,
        sonar and lasers of a robot at rest) is not decoded again."""
        self.feeds: list[Feed] = [kind(self) for kind in (*FEEDS, *self.config.extra_feeds)]
        self._by_type = {type(feed): feed for feed in self.feeds if not isinstance(feed, DeferredFeed)}
        self._handlers: dict[type[Intent], Feed] = {}
        for feed in self.feeds:
            for intent_type in feed.intent_types():
                if intent_type in self._handlers:
                    raise ValueError(f"{intent_type.__name__} is handled by two feeds")
                self._handlers[intent_type] = feed
        self.drive = self.feed(DriveFeed)
        self.drive.on_lost = self._connection_lost
        self.maps = self.feed(MapFeed)
        self.drive.busy = lambda: self.maps.downloading
        status = self.feed(StatusFeed)
        status.on_status = self.drive.note_status  # the status stream is the link's heartbeat
        self.drive.on_ping_reply = self._on_ping_reply

    def _on_ping_reply(self, name: str, payload: bytes) -> None:
        if name == "getSafeDrive":  # the cheapest request may also be the one that says safe drive's state
            self.feed(StatusFeed).on_safe_drive(payload)

    # -- the feeds' context ------------------------------------------------------------------
    @property
    def target(self) -> Target | None:
        return self._target

    @property
    def robot(self) -> RobotState:
        if self._times:
            self._robot = replace(self._robot, **self._times)
            self._times.clear()
        return self._robot

    @property
    def map(self) -> MapModel:
        return self.maps.value

    def feed(self, kind: type[F]) -> F:
        found = self._by_type.get(kind)
        if found is None:
            deferred = (f for f in self.feeds if isinstance(f, DeferredFeed) and f.entry.names(kind))
            stand_in = next(deferred, None)
            if stand_in is None:
                raise LookupError(f"this session has no {kind.__name__}")
            found = self._by_type[kind] = stand_in.loaded()
        return found  # type: ignore[return-value]

    def publish(self, change: StateChange) -> None:
        part = type(change)
        if self._published.get(part) == change:
            return
        self._published[part] = change
        try:
            self.publish_fn(change)
        except Exception:
            log.exception("publishing %s failed", part.__name__)

    def robot_update(self, **changes: Any) -> None:
        old = self._robot
        if all(k in READING_TIMES or getattr(old, k) == v for k, v in changes.items()):
            # Only a reading's time moved (a robot at rest): nothing to tell anyone, and no new value
            # built until one is read (:attr:`robot`) or something else changes.
            self._times.update((k, v) for k, v in changes.items() if k in READING_TIMES)
            return
        self._robot = replace(old, **{**self._times, **changes})
        self._times.clear()
        if self._robot == old:
            return
        self.publish(RobotChanged(self._robot))
        for feed in self.feeds:
            feed.robot_changed(self._robot)

    def notice(self, notice: Notice) -> None:
        try:
            self.notice_fn(notice)
        except Exception:
            log.exception("notice callback failed")

    def decode(self, name: str, payload: bytes) -> Any:
        last = self._decoded.get(name)
        if last is not None and last[0] == payload:  # the same bytes again (a robot at rest): same value
            return last[1]
        try:
            value = decode_payload(name, Side.REPLY, payload)
        except ProtocolError as exc:
            # Counted (the health shows it), logged sparingly: a 10 Hz stream of bad packets must
            # neither flood the log nor end the link; the next good packet is used as usual.
            health = self.drive.health
            health.bad_payloads += 1
            if health.bad_payloads <= 10 or health.bad_payloads % 1000 == 0:
                log.warning("undecodable %s packet (%d so far): %s", name, health.bad_payloads, exc)
            return None
        if len(payload) <= DECODE_CACHE_BYTES:
            self._decoded[name] = (payload, value)
        return value

    def spawn(self, coro: Coroutine[Any, Any, Any], name: str) -> None:
        task = asyncio.get_running_loop().create_task(coro, name=f"session-{name}")
        self._tasks.add(task)
        task.add_done_callback(self._task_done)

    def kick(self) -> None:
        """Run the drive loop's heart now (the lease changed). Loop thread only."""
        self.drive.kick()

    def handler_for(self, name: str) -> Handler | None:
        return next((sub.handler for sub in self._subs if sub.name == name), None)

    def sync_subscriptions(self) -> None:
        """Start or end the conditional subscriptions (``only_while``) whose condition changed."""
        client = self.client
        if client is None or not client.connected:
            return
        for sub in self._subs:
            if sub.only_while is None:
                continue
            wanted = sub.only_while()
            if wanted and sub.name not in self._held_subs:
                self._held_subs.add(sub.name)
                client.request(sub.name, sub.interval_ms, sub.handler)
            elif not wanted and sub.name in self._held_subs:
                self._held_subs.discard(sub.name)
                client.stop_request(sub.name)

    # -- intents -----------------------------------------------------------------------------
    async def dispatch(self, intent: Intent) -> Any:
        """Carry out one operator intent through the feed that handles its type.

        A :class:`Stop` always goes out, whatever the link looks like. Anything that moves the robot
        ends a held drive first. An intent the server does not offer raises NotSupported."""
        feed = self._handler(type(intent))
        if intent.needs and not isinstance(intent, Stop):
            client = self.client
            if client is None or not client.connected:
                raise ServerClosed("not connected")
            if not any(client.supports(name) for name in intent.needs):
                raise NotSupported(intent.needs[0], f"this server does not offer {intent.needs[0]}")
        if intent.moves:
            self.drive.end_drive(f"{intent.label.lower()} takes over")
        result = feed.handle(intent)
        if asyncio.iscoroutine(result) or isinstance(result, asyncio.Future):
            return await result
        return result

    def _handler(self, kind: type[Intent]) -> Feed:
        for cls in kind.__mro__:
            feed = self._handlers.get(cls)
            if feed is not None:
                return feed
        raise NotSupported(kind.__name__, f"no part of this session handles {kind.__name__}")

    # -- connect / disconnect ----------------------------------------------------------------
    @property
    def connected(self) -> bool:
        return self.client is not None and self.client.connected

    @property
    def guardian(self) -> GuardianSeat | None:
        """This session's place at its guardian (None without one): ``state`` says if it is armed."""
        return self.drive.guardian.seat

    async def connect(self, target: Target) -> None:
        """Connect and set up the session; raises the :class:`ClientError` after publishing FAILED.

        A :meth:`disconnect` (or another ``connect``) while this one is still logging in cancels it.
        """
        self._cancel_connecting()
        self._connecting = asyncio.current_task()
        if self.connected and self.client.drove:  # type: ignore[union-attr]  # our drive: stop it first
            self.drive.send_stop("connecting elsewhere")
        await self._forget()
        self._target = target
        self._set_connection(
            phase=Phase.CONNECTING, host=target.host, port=target.port, user=target.user,
            profile=target.profile, offers=frozenset(), error="", error_kind="", attempt=0, retry_in=None,
        )  # fmt: skip
        self.drive.ensure_heart()
        try:
            await self._open(target)
        except ClientError as exc:
            if self._target is target:
                # The same words as ``rtmu doctor``: what failed, then what to do next.
                self._set_connection(phase=Phase.FAILED, error=explain(exc).sentence(), error_kind=exc.kind)
            raise
        finally:
            if self._connecting is asyncio.current_task():
                self._connecting = None

    def _cancel_connecting(self) -> None:
        task, self._connecting = self._connecting, None
        if task is not None and task is not asyncio.current_task() and not task.done():
            task.cancel()

    async def _open(self, target: Target) -> None:
        client = self.client_factory(lambda error: self._on_client_closed(client, error))
        await client.connect(target, timeout=self.config.connect_timeout, role=self.config.role)
        if self._target is not target:  # disconnected (or re-targeted) meanwhile
            await client.disconnect()
            raise ServerClosed("the connection attempt was cancelled")
        self.client = client
        self.drive.stop_first()  # lost while driving: the robot may still move, a stop goes out first
        self._subs = merged(
            applicable((s for f in self.feeds for s in f.subscriptions(client)), client.supports)
        )
        self._held_subs.clear()
        for feed in self.feeds:
            for sub in self._subs_of(feed, client):
                client.request(sub.name, sub.interval_ms, sub.handler)
            feed.connected(client)
        self.sync_subscriptions()
        offers = frozenset(e.name for e in client.datalist)
        tag, wanted, sent = client.server_words
        self._set_connection(
            phase=Phase.CONNECTED, offers=offers, error="", error_kind="", retry_in=None,
            server_tag=tag, server_protocol=wanted, sent_protocol=sent,
        )  # fmt: skip
        self.kick()

    def _subs_of(self, feed: Feed, client: AriaClient) -> list[Subscription]:
        """The merged, unconditional subscriptions this feed is the first to want (made before its
        ``connected``: a feed's first question may be answered through them)."""
        names = {s.name for s in feed.subscriptions(client)}
        earlier = {s.name for f in self.feeds[: self.feeds.index(feed)] for s in f.subscriptions(client)}
        return [s for s in self._subs if s.name in names - earlier and s.only_while is None]

    async def disconnect(self) -> None:
        """Stop the robot, say goodbye, forget the robot's values. Returns within a fraction of a second."""
        self._cancel_connecting()
        if self.connected and self.client.drove:  # type: ignore[union-attr]  # only our own drive
            self.drive.send_stop("disconnect")
        await self._forget()
        self._set_connection(
            phase=Phase.DISCONNECTED, offers=frozenset(), error="", error_kind="", retry_in=None
        )
        self.drive.publish_health()

    async def _forget(self) -> None:
        """End the connection (if any) and every feed's share of it: the next one starts from nothing."""
        self._cancel_reconnect()
        self._target = None
        self.lease.end(EndReason.DISCONNECTED)
        await self._drop_client()
        self._robot = RobotState()
        self._times.clear()
        self.publish(RobotChanged(self._robot))
        for feed in self.feeds:
            feed.disconnected()

    async def close(self) -> None:
        """Disconnect and end every task (runner shutdown); each wait is bounded."""
        await self.disconnect()
        self.drive.guardian.end()
        await self.drive.end_heart(TASK_END_TIMEOUT)

    async def _drop_client(self) -> None:
        client, self.client = self.client, None
        self.drive.guardian.close()
        self._cancel_tasks()
        self.drive.health.stop()
        self.drive.governor.reset()
        self._subs = []
        if client is not None:
            await client.disconnect()

    def _cancel_tasks(self) -> None:
        for task in list(self._tasks):
            task.cancel()

    def _on_client_closed(self, client: AriaClient, error: ClientError) -> None:
        if client is self.client:
            self._connection_lost(error)

    def _connection_lost(self, error: ClientError) -> None:
        """Not our choice: the server died, closed, or the link was lost."""
        client, self.client = self.client, None
        for feed in self.feeds:
            feed.lost()
        self._cancel_tasks()
        if client is not None:
            self._spawn_detached(client.disconnect())
        target = self._target
        if target is not None and target.auto_reconnect and worth_retrying(error):
            self._set_connection(phase=Phase.RECONNECTING, error=str(error), error_kind=error.kind, attempt=0)
            self._reconnect_task = asyncio.get_running_loop().create_task(self._reconnect(target))
        else:
            self._set_connection(phase=Phase.FAILED, error=str(error), error_kind=error.kind, retry_in=None)

    async def _reconnect(self, target: Target) -> None:
        backoff = self.config.backoff()
        at_once = self.drive.stop_on_connect  # lost while driving: the first try carries a stop, no wait
        while self._target is target:
            delay = 0.0 if at_once else backoff.next_delay()
            at_once = False
            self._set_connection(phase=Phase.RECONNECTING, attempt=backoff.attempt, retry_in=round(delay, 1))
            await asyncio.sleep(delay)
            if self._target is not target:
                return
            try:
                await self._open(target)
            except ClientError as exc:
                if not worth_retrying(exc):
                    self._set_connection(
                        phase=Phase.FAILED, error=str(exc), error_kind=exc.kind, retry_in=None
                    )
                    return
                self._set_connection(error=str(exc), error_kind=exc.kind)
                continue
            self.notice(
                Notice.info(
                    Kind.LINK,
                    _("Reconnected to {host}:{port}; press a key to drive again").format(
                        host=target.host, port=target.port
                    ),
                )
            )
            return

    def _cancel_reconnect(self) -> None:
        task, self._reconnect_task = self._reconnect_task, None
        if task is not None and task is not asyncio.current_task():
            task.cancel()

    def _spawn_detached(self, coro: Coroutine[Any, Any, Any]) -> None:
        task = asyncio.get_running_loop().create_task(coro)
        task.add_done_callback(lambda t: t.cancelled() or t.exception())

    def _task_done(self, task: asyncio.Task[Any]) -> None:
        self._tasks.discard(task)
        if not task.cancelled() and task.exception() is not None:
            exc = task.exception()
            if not isinstance(exc, ClientError):
                log.error("session task %s failed", task.get_name(), exc_info=exc)

    def _set_connection(self, **changes: Any) -> None:
        self._connection = replace(self._connection, **changes)
        self.publish(ConnectionChanged(self._connection))

    # -- for the runner and tests --------------------------------------------------------------
    async def step(self, timeout: float = STEP_TIMEOUT) -> None:
        """Wait until the drive loop's heart has run once more (tests drive a fake clock with this)."""
        await self.drive.step(timeout)

    async def stop_and_flush(self, timeout: float = 0.5) -> bool:
        """Stop now; True once the stop has been handed to the kernel (or there was nothing to stop)."""
        return await self.drive.stop_and_flush(timeout)

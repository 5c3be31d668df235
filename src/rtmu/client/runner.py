"""The network thread and its thread-safe facade: what a UI (or a script) holds.

Concurrency design
------------------
* One **network thread** owns an asyncio loop; the :class:`Session` (socket,
  subscriptions, health, drive governor, reconnect) lives only there. It never
  waits for the UI, so a long redraw cannot delay a packet (gtk4-notes.md
  measured 11 ms p99 with a 300 ms UI stall this way, against 290 ms with one
  shared loop).
* The **UI thread** calls the methods below; each returns at once (they hand
  work to the loop with ``call_soon_threadsafe`` and give back a
  ``concurrent.futures.Future`` for those who care). Every operator intent crosses
  in ONE way, :meth:`ClientRunner.send`: the session hands it to the feed that
  handles its type.
* Results travel back through ``post(fn)``, the injectable "run this on the UI
  thread" function: GTK passes ``GLib.idle_add``; tests and scripts pass a
  direct call or a queue. Posted functions return None, so ``idle_add`` runs
  them once. Every published change (:data:`rtmu.values.state.StateChange`) is handed
  to the runner's ``sink`` (a :class:`~rtmu.model.observables.RobotModel`, a recorder, a
  test list) on the UI thread; only real changes get posted. The runner never
  imports the UI thread's state: it knows the sink only by its ``apply``.
* Calls that may block (keyring lookups) go to :meth:`ClientRunner.run_blocking`:
  a worker thread that is neither the UI thread nor the network loop.

Safety design
-------------
The robot moves only while the operator keeps asking, and every layer that can
fail has something behind it:

1. **The UI renews a lease.** A drive key grants a :class:`DriveLease`; the UI's
   own 10 Hz timer renews it while the key is held. Release, focus loss, a stop,
   a stale link or a lease not renewed for 300 ms (a frozen or busy UI) end it,
   and a dead lease never comes back without a fresh key press (also after a
   reconnect). A UI that only waited for a CPU is credited that time by the
   :class:`~rtmu.client.lease_keeper.LeaseKeeper` (up to 1 s).
2. **The network loop sends ``ratioDrive`` only while the lease is fresh**, at
   10 Hz, and zero ratios + ``stop`` the moment it ends or lapses, or the link
   health is not OK (no status for the limit learned for this link, 0.3–0.45 s in
   the window — ``base.link_timing`` —, or a ping unanswered). It wakes at the
   exact expiry, so a lapse costs at most the lease's 300 ms. ``disconnect``,
   ``close``, connecting elsewhere and ``stop()`` all send zero ratios + ``stop``.
3. **If the network loop itself is blocked**, nothing can be sent — neither the
   resends nor the stop: a release or a stop waits until the loop runs again. So
   the loop must never run slow work: map packets → arrays runs in an executor
   (:mod:`~rtmu.client.mapload`), payload decoding is a few microseconds, and the
   feeds' handlers only update a shadow and ``post`` to the UI.
   :meth:`ClientRunner.loop_lag` says how long the loop has been working without
   going back to wait for the network (:mod:`~rtmu.client.loop_watch` watches its
   selector), so a window can warn (e.g. above 0.5 s) that driving commands may
   not be getting out — with no timer waking a still loop to tell.
4. **The guardian** (``SessionConfig(guardian=True)``, :mod:`rtmu.guardian`): a
   separate process with its own login that stops the robot when this process
   is killed, stopped by a signal, or silent past its lease while driving; the
   network loop and the UI (:meth:`ClientRunner.ui_heartbeat`) beat for it.
5. **ARIA's own watchdog** on the server stops a robot that hears no drive
   command for 2 s — the last backstop when this process is frozen, suspended or
   killed (``rtmu drive`` handles the signals that would kill it: see
   ``rtmu.subcommands._common``).
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import logging
import threading
import time
from collections.abc import Awaitable, Callable
from typing import Any, TypeVar, overload

from ..base.notices import Kind, Notice
from ..base.priority import raise_priority
from ..values.intents import Intent, Stop
from ..values.state import StateChange, StateSink
from ..values.target import Target
from . import lease_keeper
from .config_feed import ConfigFeed
from .connection import AriaClient
from .errors import ClientError, ClientTimeout
from .lease import LEASE_TTL, DriveLease, EndReason
from .lease_keeper import LeaseKeeper
from .link import Opener
from .loop_watch import WatchedSelector
from .session import Session
from .session_config import SessionConfig

log = logging.getLogger(__name__)

T = TypeVar("T")
SHUTDOWN_TIMEOUT = 0.5
"""How long the network thread waits for its cancelled tasks to finish before it ends anyway."""
Post = Callable[[Callable[[], None]], Any]


def settle(future: concurrent.futures.Future[bool], timeout: float) -> bool:
    """The future's answer, or False when it fails or has none within ``timeout`` s (then cancelled)."""
    try:
        return bool(future.result(timeout))
    except (concurrent.futures.TimeoutError, Exception):
        future.cancel()
        return False


def call_directly(fn: Callable[[], None]) -> None:
    """The trivial ``post``: run on the calling (network) thread. For scripts and tests."""
    fn()


class ClientRunner:
    """Use as ``with ClientRunner(robot_model, post=GLib.idle_add) as runner:`` (or ``start()``/``close()``).

    Implements ``rtmu.control.ports.ClientLink``. All public methods are thread-safe.
    """

    def __init__(
        self,
        sink: StateSink | None = None,
        *,
        post: Post = call_directly,
        clock: Callable[[], float] = time.monotonic,
        config: SessionConfig | None = None,
        lease_ttl: float = LEASE_TTL,
        opener: Opener | None = None,
    ) -> None:
        self.sink = sink
        self.opener = opener
        """Makes each connection's link (None: TCP); a flight recorder passes one that tees the bytes."""
        self.post = post
        self.clock = clock
        self.config = config or SessionConfig()
        self.lease = DriveLease(ttl=lease_ttl, clock=clock)
        # Run-queue waits are real time: credited only to a lease on the real clock (not a test's).
        keep = clock is time.monotonic and lease_keeper.CREDITING
        self.keeper = LeaseKeeper(self.lease, beat=self._beat_ui_at) if keep else None  # hooks the lease
        self.on_notice: Callable[[Notice], None] | None = None
        """``on_notice(notice)``, called on the UI thread (through ``post``)."""
        self.on_publish: Callable[[StateChange], None] | None = None
        """Optional tap on every published value, called on the *network* thread (benchmarks, scripts)."""
        self.on_notice_sent: Callable[[Notice], None] | None = None
        """Optional tap on every notice as it is raised (network thread mostly): a flight recorder."""
        self.on_stop: Callable[[str, bool], None] | None = None
        """Optional tap: ``on_stop(reason, sent)`` for every zero-ratios + ``stop`` (network thread)."""
        self.on_config_updated: Callable[[], None] | None = None
        """Called on the UI thread when another client changed the server's configuration."""
        self._config_post_pending = threading.Event()
        self._watch = WatchedSelector(clock)
        self.loop = asyncio.SelectorEventLoop(self._watch)
        self.session: Session | None = None
        self._thread = threading.Thread(target=self._run, name="rtmu-network", daemon=True)
        self._ready = threading.Event()
        self._closed = False
        self._blocking = concurrent.futures.ThreadPoolExecutor(1, thread_name_prefix="rtmu-blocking")
        """One worker for :meth:`run_blocking` (keyring calls), apart from the network loop."""

    # -- lifecycle ---------------------------------------------------------------------------
    def start(self) -> ClientRunner:
        if self.keeper is not None:
            self.keeper.start()
        self._thread.start()
        if not self._ready.wait(5):
            raise RuntimeError("the network thread did not start")
        return self

    def __enter__(self) -> ClientRunner:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _run(self) -> None:
        raise_priority()  # where allowed: the loop that sends drives and stops must run on time
        asyncio.set_event_loop(self.loop)
        factory = None
        opener = self.opener
        if opener is not None:

            def factory(on_close: Callable[[ClientError], None]) -> AriaClient:
                return AriaClient(on_close=on_close, clock=self.clock, opener=opener)

        self.session = Session(
            self.lease,
            self._publish,
            self._notice,
            clock=self.clock,
            config=self.config,
            client_factory=factory,
        )
        self.session.drive.on_stop = self._stopped
        self.session.feed(ConfigFeed).listener = self._config_updated
        self.lease.on_change = self._lease_changed
        self._ready.set()
        try:
            self.loop.run_forever()
        finally:
            with contextlib.suppress(Exception):
                pending = asyncio.all_tasks(self.loop)
                for task in pending:
                    task.cancel()
                if pending:  # bounded: a task that ignores its cancel must not keep the thread alive
                    self.loop.run_until_complete(asyncio.wait(pending, timeout=SHUTDOWN_TIMEOUT))
            self.loop.close()

    def close(self, timeout: float = 2.0) -> None:
        """Stop the robot, disconnect, end the thread. Idempotent; returns within ``timeout``."""
        if self.keeper is not None:
            self.keeper.close()
        if self._closed or not self._thread.is_alive():
            self._closed = True
            self._blocking.shutdown(wait=False, cancel_futures=True)
            return
        self._closed = True
        self.lease.on_change = None
        with contextlib.suppress(Exception):  # on the loop even though submit() now refuses work
            self._on_loop(self._session.close).result(timeout)
        self.loop.call_soon_threadsafe(self.loop.stop)
        self._thread.join(timeout)
        self._blocking.shutdown(wait=False, cancel_futures=True)

    def loop_lag(self) -> float | None:
        """Seconds the network loop has been working since it last waited for the network (0 while it
        waits); None before start or after close. Any thread may ask (two plain reads).

        A loop that runs its callbacks goes back to waiting within milliseconds. Much more means it
        is blocked: drive resends and stops are not going out either — a window says so.
        """
        if self._closed or not self._thread.is_alive():
            return None
        return self._watch.busy_for()

    @property
    def _session(self) -> Session:
        assert self.session is not None, "start() the runner first"
        return self.session

    # -- crossing threads --------------------------------------------------------------------
    @overload
    def submit(self, fn: Callable[..., Awaitable[T]], *args: Any) -> concurrent.futures.Future[T]: ...
    @overload
    def submit(self, fn: Callable[..., T], *args: Any) -> concurrent.futures.Future[T]: ...
    def submit(self, fn: Callable[..., Any], *args: Any) -> concurrent.futures.Future[Any]:
        """Run ``fn(*args)`` (plain or async) on the network loop; a Future for its result."""
        if self._closed:
            failed: concurrent.futures.Future[Any] = concurrent.futures.Future()
            failed.set_exception(ClientError("the client has been closed"))
            return failed
        return self._on_loop(fn, *args)

    def _on_loop(self, fn: Callable[..., Any], *args: Any) -> concurrent.futures.Future[Any]:
        async def run() -> Any:
            result = fn(*args)
            if asyncio.iscoroutine(result) or isinstance(result, asyncio.Future):
                return await result
            return result

        return asyncio.run_coroutine_threadsafe(run(), self.loop)

    @overload
    def call(self, fn: Callable[..., Awaitable[T]], *args: Any, timeout: float = ...) -> T: ...
    @overload
    def call(self, fn: Callable[..., T], *args: Any, timeout: float = ...) -> T: ...
    def call(self, fn: Callable[..., Any], *args: Any, timeout: float = 15.0) -> Any:
        """Blocking :meth:`submit` for scripts and tests (never from the GTK thread)."""
        future = self.submit(fn, *args)
        try:
            return future.result(timeout)
        except concurrent.futures.TimeoutError:
            future.cancel()
            raise ClientTimeout(f"the network thread did not finish within {timeout:g} s") from None

    def _fire(
        self, fn: Callable[..., Any], *args: Any, kind: Kind = Kind.COMMAND
    ) -> concurrent.futures.Future[Any]:
        """Submit, and tell the operator (``on_notice``, as a notice of ``kind``) if it fails."""
        future = self.submit(fn, *args)
        future.add_done_callback(lambda done: self._report(done, kind))
        return future

    def _report(self, future: concurrent.futures.Future[Any], kind: Kind) -> None:
        if future.cancelled():
            return
        exc = future.exception()
        if isinstance(exc, (ClientError, ValueError)):  # the server's refusal, or an argument out of bounds
            self._notice(Notice.error(kind, str(exc)))
        elif exc is not None:
            log.error("network call failed", exc_info=exc)
            self._notice(Notice.error(kind, f"internal error: {exc}"))

    def _publish(self, change: StateChange) -> None:
        tap = self.on_publish
        if tap is not None:
            tap(change)
        sink = self.sink
        if sink is None:
            return
        self.post(lambda: sink.apply(change))

    def _stopped(self, reason: str, sent: bool) -> None:
        tap = self.on_stop
        if tap is not None:
            tap(reason, sent)

    def notify(self, notice: Notice) -> None:
        """Tell the operator (``on_notice``, on the UI thread) from any thread: a recorder's problems."""
        self._notice(notice)

    def _notice(self, notice: Notice) -> None:
        tap = self.on_notice_sent
        if tap is not None:
            with contextlib.suppress(Exception):
                tap(notice)

        def show() -> None:
            hook = self.on_notice
            if hook is not None:
                hook(notice)

        self.post(show)

    def _lease_changed(self) -> None:
        session = self.session
        if session is None or self.loop.is_closed():
            return
        with contextlib.suppress(RuntimeError):  # loop already closed
            self.loop.call_soon_threadsafe(session.kick)

    # -- the controller's link (rtmu.control.ports.ClientLink) -------------------------------
    def connect(self, target: Target) -> concurrent.futures.Future[None]:
        """Connect in the background; the model's ``connection`` shows progress and failure."""
        session = self._session
        future = self.submit(lambda: session.connect(target))
        future.add_done_callback(lambda f: f.cancelled() or f.exception())  # failure is shown by the model
        return future

    def disconnect(self) -> concurrent.futures.Future[None]:
        return self._fire(self._session.disconnect, kind=Kind.CONNECTION)

    def send(self, intent: Intent) -> concurrent.futures.Future[Any]:
        """The one way an operator's intent crosses to the network thread (:meth:`Session.dispatch`).

        Returns at once; the Future holds the feed's answer (a map, a configuration, whether the
        server took a command). A failure is also told to the operator (``on_notice``, as a notice
        of the intent's kind). A :class:`Stop` ends the lease here first, so a drive cannot be
        renewed while the stop is on its way."""
        if isinstance(intent, Stop):
            self.lease.end(EndReason.STOPPED)
        return self._fire(self._session.dispatch, intent, kind=intent.kind)

    def stop(self) -> concurrent.futures.Future[Any]:
        """Zero ratios and ``stop`` at once, whatever the link health says."""
        return self.send(Stop())

    def stop_and_wait(self, timeout: float = 0.5) -> bool:
        """Blocking :meth:`stop`: True once zero ratios + ``stop`` have left this process.

        For a UI about to be suspended or killed (a SIGTSTP or SIGQUIT handler): call it first,
        then let the signal take its course. False after ``timeout`` s (the loop is blocked or the
        server does not read) or once the runner is closed. Not from the network thread.
        """
        return settle(self.stop_flushing(timeout), timeout + 0.1)

    def stop_flushing(self, timeout: float = 0.5) -> concurrent.futures.Future[bool]:
        """:meth:`stop` now; the Future says (bounded by ``timeout``) whether it left this process.

        Several runners can be stopped at once this way and their futures awaited together.
        """
        self.lease.end(EndReason.STOPPED)
        if self._closed or self.session is None or not self._thread.is_alive():
            done: concurrent.futures.Future[bool] = concurrent.futures.Future()
            done.set_result(False)
            return done
        return self._on_loop(self._session.stop_and_flush, timeout)

    def _config_updated(self) -> None:
        """Network loop: tell the UI once per burst (a flood of broadcasts is one post, not thousands)."""
        if self.on_config_updated is None or self._config_post_pending.is_set():
            return
        self._config_post_pending.set()

        def deliver() -> None:
            self._config_post_pending.clear()
            fn = self.on_config_updated
            if fn is not None:
                fn()

        self.post(deliver)

    def run_blocking(
        self, fn: Callable[[], T], done: Callable[[T | None], None], *, timeout: float = 30.0
    ) -> concurrent.futures.Future[T]:
        """Run a call that may block (a keyring lookup: D-Bus, an unlock prompt) off the UI thread.

        ``fn`` runs in a worker thread — neither the UI thread nor the network loop, which must
        keep its timing — and ``done(result)`` is then posted to the UI thread; ``done(None)``
        if ``fn`` raised or took longer than ``timeout`` s.
        """
        future: concurrent.futures.Future[T] = self._blocking.submit(fn)
        answered = threading.Event()

        def deliver(result: T | None) -> None:
            if not answered.is_set():
                answered.set()
                self.post(lambda: done(result))

        def finished(f: concurrent.futures.Future[T]) -> None:
            if f.cancelled() or f.exception() is not None:
                if f.exception() is not None:
                    log.warning("background call failed: %s", f.exception())
                deliver(None)
            else:
                deliver(f.result())

        future.add_done_callback(finished)
        timer = threading.Timer(timeout, lambda: deliver(None))
        timer.daemon = True
        timer.start()
        future.add_done_callback(lambda f: timer.cancel())
        return future

    def sync(self, timeout: float = 2.0) -> None:
        """Wait until the network side has handled everything submitted so far and run one heart step."""
        self.call(self._session.step, timeout=timeout)

    def ui_heartbeat(self) -> bool:
        """The UI thread is alive: call every ``rtmu.guardian.handle.BEAT_PERIOD`` s from its timer
        while the guardian is armed (the answer: whether it still is).

        The guardian process stops the robot when these (or the network thread's) stop while
        driving. A plain write to a pipe; never blocks.
        """
        session = self.session
        guardian = session.guardian if session is not None else None
        if guardian is None:
            return False
        guardian.beat_ui()
        return guardian.armed

    def _beat_ui_at(self, at: float) -> None:
        """The lease keeper's beat for a UI thread that only waited for a CPU (keeper thread)."""
        session = self.session
        guardian = session.guardian if session is not None else None
        if guardian is not None:
            guardian.beat_ui(at)

    def status_age(self) -> float | None:
        """Seconds since the last status packet, read now; None when not connected.

        For a UI timer that shows how old the data is: the model hears only real
        changes (a robot standing still publishes nothing new), so the age cannot
        be derived from it. A plain read of two floats the network thread writes.
        """
        session = self.session
        if session is None or session.client is None:
            return None
        return session.drive.health.status_age(self.clock())

"""The drive loop: the lease turned into ``ratioDrive``, the link's health, the pings, the stops.

Its heart is one task that wakes at the exact moments something is due — a ``ratioDrive``
resend, the lease's expiry, the status going stale — or when the UI changes the lease, and then
asks the pure :class:`~rtmu.client.lease.DriveGovernor` and
:class:`~rtmu.client.health.HealthMonitor` what to do. Because it never waits for the UI thread,
a long redraw cannot delay a packet; because motion needs a lease the UI keeps renewing, a frozen
UI cannot keep the robot moving. ``stop`` always wins and is always sent, whatever the link looks
like; anything else that moves the robot ends a held drive first (:meth:`DriveFeed.end_drive`).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import time
from collections.abc import Callable
from typing import Any, ClassVar

from ..base.i18n import _
from ..base.notices import Kind, Notice
from ..protocol.client_connection import payload_name
from ..protocol.payloads import Payload
from ..protocol.payloads.drive import RatioDrive
from ..values.intents import Intent, MoveDistance, Stop, TurnBy
from ..values.state import HealthChanged, LinkHealth, LinkLevel
from .connection import AriaClient
from .errors import ClientError, ClientTimeout, ServerClosed
from .feed import Feed, FeedContext
from .guardian_link import GuardianLink
from .health import HealthMonitor, ping_data
from .lease import DriveGovernor, EndReason, SendRatios, SendStop

log = logging.getLogger(__name__)

HEART_MAX_SLEEP = 0.25
HEART_IDLE_SLEEP = 1.0
"""Longest sleep while nothing is driven: a grant, a stop and a returning link wake the heart at once,
and the link's next change of level comes by a timer each status moves on (``_level_watch``) — so at
rest it wakes once a second (a guardian's reports, the health published), not at each deadline."""
HOLD_SAID_AFTER = 1.0
"""A drive held back this long for the guardian (its login is slow) is said, once."""
STEP_TIMEOUT = 2.0
"""``step()`` gives up (ClientTimeout) if the heart has not run within this many seconds."""


class DriveFeed(Feed):
    """Owns the lease's governor, the health monitor, the heart task, the pings and the guardian."""

    handles: ClassVar[tuple[type[Intent], ...]] = (Stop, TurnBy, MoveDistance)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        config = ctx.config
        self.lease = ctx.lease
        self.governor = DriveGovernor(self.lease)
        self.health = HealthMonitor(
            config.status_interval_ms / 1000.0, lost_after=config.lost_after, ping_ceiling=config.ping_timeout
        )
        self.guardian = GuardianLink(ctx.notice, config)
        self._held_since: float | None = None
        """Since when a live lease has waited for the guardian to be armed (see :meth:`_unguarded`)."""
        self._held_said: int | None = None
        self.packets_sent = 0
        self.on_stop: Callable[[str, bool], None] | None = None
        """Optional tap (a flight recorder): ``on_stop(reason, sent)`` after every zero-ratios + ``stop``."""
        self.on_lost: Callable[[ClientError], None] = lambda error: None
        """The session's reaction to a lost link (reconnect, or say it failed)."""
        self.on_ping_reply: Callable[[str, bytes], None] = lambda name, payload: None
        """Each ping's answer (the session hands a ``getSafeDrive`` answer to the status feed)."""
        self.busy: Callable[[], bool] = lambda: False
        """True while a long reply (the map) is arriving: its bytes keep the link alive."""
        self._kick = asyncio.Event()
        self._stepped = asyncio.Event()
        self._heart_task: asyncio.Task[None] | None = None
        self._level_watch: asyncio.TimerHandle | None = None
        """At rest: the timer that wakes the heart when the link's level would next change — moved on
        by every status (:meth:`note_status`) rather than waking the heart at each deadline a status
        then moves (three times a second at rest; None while driving, where the heart wakes often)."""
        self.stop_on_connect = False
        """The link was lost while driving: the next connection (made at once) begins with a stop."""

    # -- the connection --------------------------------------------------------------------------
    def stop_first(self) -> None:
        """A new connection is up: if ours was lost while driving, the robot may still be moving —
        a stop is the first thing sent on it (the guardian's own link may have gone with ours)."""
        if self.stop_on_connect:
            self.stop_on_connect = False
            self.send_stop("reconnected after the link was lost while driving")

    def connected(self, client: AriaClient) -> None:
        target = self.ctx.target
        if target is not None and client.supports("ratioDrive"):
            self.guardian.start(target)  # (a session without a guardian has no seat: nothing happens)
        # Whatever happened before, the robot stays still until a fresh key press.
        self.lease.end(EndReason.DISCONNECTED)
        self.governor.reset()
        self.health.start(self.ctx.clock())
        where = f"{target.host}:{target.port}" if target is not None else "the server"
        self.health.bind(where, lambda: client.last_packet_at, client.undecided)
        self.ctx.spawn(self._ping_loop(client), "ping")
        self.kick()

    def disconnected(self) -> None:
        self.stop_on_connect = False  # forgotten on purpose: the next connection may be another robot
        self.guardian.close()
        self.health.stop()
        self.governor.reset()

    def lost(self) -> None:
        """Our link died, not by our choice: while driving, only the guardian (its own link) can stop —
        and the first reconnect, made at once, begins with a stop (:meth:`stop_first`)."""
        self.stop_on_connect = self.governor.driving
        self.guardian.lost(driving=self.governor.driving)
        self.lease.end(EndReason.DISCONNECTED)
        self.governor.reset()
        self.health.stop()
        self.publish_health()

    # -- intents -----------------------------------------------------------------------------
    def handle(self, intent: Intent) -> None:
        if isinstance(intent, Stop):
            self.stop_now(intent.reason)
        elif isinstance(intent, TurnBy):
            self.require("turnByAngle").send("turnByAngle", float(intent.degrees))
            self.packets_sent += 1
        elif isinstance(intent, MoveDistance):
            self.require("moveDist").send("moveDist", float(intent.mm))
            self.packets_sent += 1

    def stop_now(self, reason: str = "stop key") -> None:
        """The stop key: always sent at once, even when the link looks stale."""
        self.lease.end(EndReason.STOPPED)
        self.send_stop(reason)
        self.governor.reset()
        self.kick()

    async def stop_and_flush(self, timeout: float = 0.5) -> bool:
        """:meth:`stop_now`, then wait (bounded) until the stop has been handed to the kernel.

        True when it has (or there was no connection to stop); for callers about to freeze the
        process (Ctrl-Z) or end it abruptly.
        """
        self.stop_now()
        client = self.ctx.client
        if client is None or not client.connected:
            return True
        return await client.flush(timeout)

    def end_drive(self, reason: str) -> None:
        """Something else is about to move the robot: a held drive ends first (its stop goes out
        before that command), or the next ``ratioDrive`` would take the robot back at once."""
        driving = self.governor.driving
        self.lease.end(EndReason.STOPPED)
        if driving:
            self.send_stop(reason)
            self.governor.reset()

    def send(self, what: str | Payload, *args: Any) -> bool:
        """Send if connected and offered; a typed payload names its data (``send(RatioDrive(…))``)."""
        client = self.ctx.client
        name = what if isinstance(what, str) else payload_name(what)
        if client is None or not client.connected or not client.supports(name):
            return False
        try:
            client.send(what, *args)
        except ClientError:
            return False
        self.packets_sent += 1
        return True

    def send_stop(self, reason: str = "") -> None:
        """Zero ratios, then ``stop`` — whatever the link health looks like. ``reason`` is for ``on_stop``."""
        sent = self.send(RatioDrive(0.0, 0.0, 0.0))
        sent = self.send("stop") or sent
        log.info("stop %s: %s (%s)", "sent" if sent else "not sent", reason or "stop", self._link_account())
        tap = self.on_stop
        if tap is not None:
            with contextlib.suppress(Exception):
                tap(reason or "stop", sent)
        self.guardian.disarm()

    def _link_account(self) -> str:
        """The link's figures at a stop, for the log: a false stop's cause is read from them."""
        now = self.ctx.clock()
        health = self.health
        age = health.status_age(now)
        aged = "-" if age is None else f"{age * 1000:.0f} ms"
        jitter = health.timing(now).jitter * 1000
        late = health.wake_lateness.value() * 1000
        client = self.ctx.client
        unread = 0 if client is None else client.unread()
        return (
            f"status age {aged}, limit {health.stale_limit(now) * 1000:.0f} ms, jitter {jitter:.0f} ms, "
            f"wake late {late:.0f} ms, unread {unread} B, load {os.getloadavg()[0]:.1f}"
        )

    # -- status and pings ----------------------------------------------------------------------
    def note_status(self, at: float) -> None:
        """A status packet arrived at ``at``: the link's heartbeat."""
        was_ok = self.health.level(at) is LinkLevel.OK
        self.health.note_status(at)
        if not was_ok:
            self.kick()  # the link came back: re-evaluate at once
        elif self._level_watch is not None:
            self._watch_level()  # at rest: the deadline moves on with the status, nothing wakes

    async def _ping_loop(self, client: AriaClient) -> None:
        name = ping_data(client.datalist)
        if name is None:
            return
        config = self.ctx.config
        while client.connected:
            started = time.perf_counter()
            try:
                reply = await client.ask_in_time(name, self.health.ping_deadline(self.ctx.clock()))
            except ClientTimeout:
                # The server may have stopped reading: it would not hear a stop either.
                self.health.note_ping_timeout()
                self.publish_health()
                self.kick()
            except ClientError:
                return
            else:
                self.health.note_rtt(time.perf_counter() - started, self.ctx.clock())
                self.on_ping_reply(name, reply.payload)
                self.publish_health()
            await asyncio.sleep(config.ping_interval)

    def _unguarded(self, now: float) -> bool:
        """True while no drive may start: the guardian is still being armed for this robot (or it is
        not the robot that may drive). A held drive then waits — its lease stays the operator's, and
        the first ``ratioDrive`` goes once the guardian is armed; the window's controller refuses the
        key before it gets here, saying why. A drive already going when that happens is ended."""
        why = self.guardian.waiting_reason()
        if why is None:
            self._held_since = None
            return False
        view = self.lease.view(now)
        if self.governor.driving:  # (a stop that ended it already — a new selection — said its own words)
            if self.lease.end(EndReason.STOPPED, view.generation):
                self.ctx.notice(
                    Notice.stopped(
                        Kind.SAFETY, _("Stopped: {why}. Press again once it is armed.").format(why=why)
                    )
                )
        elif view.live:
            if self._held_since is None:
                self._held_since = now
            elif now - self._held_since >= HOLD_SAID_AFTER and self._held_said != view.generation:
                self._held_said = view.generation
                self.ctx.notice(Notice.warning(Kind.SAFETY, _("Not driving yet: {why}").format(why=why)))
        return True

    def publish_health(self, now: float | None = None) -> None:
        now = self.ctx.clock() if now is None else now
        client = self.ctx.client
        if client is None or not self.health.running:
            self.ctx.publish(HealthChanged(LinkHealth(rtt_ms=None)))
            return
        self.ctx.publish(HealthChanged(self.health.snapshot(now, client.drops)))

    # -- the heart -----------------------------------------------------------------------------
    def kick(self) -> None:
        """Run the heart now (the lease changed, or status came back). Loop thread only."""
        self._kick.set()

    def ensure_heart(self) -> None:
        if self._heart_task is None or self._heart_task.done():
            self._heart_task = asyncio.get_running_loop().create_task(self._heart(), name="session-heart")

    def _watch_level(self) -> None:
        """(Re)arm the rest timer that kicks the heart when the link's level would next change."""
        self._unwatch_level()
        now = self.ctx.clock()
        delay = self.health.next_change(now) - now
        if delay == float("inf"):
            return
        try:
            loop = asyncio.get_running_loop()
        except RuntimeError:  # a status handed over outside the loop (a test by hand): the heart looks itself
            return
        self._level_watch = loop.call_later(max(0.0, delay), self.kick)

    def _unwatch_level(self) -> None:
        if self._level_watch is not None:
            self._level_watch.cancel()
            self._level_watch = None

    async def end_heart(self, timeout: float) -> None:
        self._unwatch_level()
        task, self._heart_task = self._heart_task, None
        if task is not None:
            task.cancel()
            await asyncio.wait({task}, timeout=timeout)

    async def step(self, timeout: float = STEP_TIMEOUT) -> None:
        """Wait until the heart has run once more (tests drive a fake clock with this).

        Raises :class:`ClientTimeout` if it has not run within ``timeout`` s.
        """
        self.ensure_heart()
        self._stepped.clear()
        self.kick()
        try:
            async with asyncio.timeout(timeout):
                await self._stepped.wait()
        except TimeoutError:
            raise ClientTimeout(f"the session heart did not run within {timeout:g} s") from None

    async def _heart(self) -> None:
        while True:
            self._kick.clear()
            now = await self._judged_now()
            try:
                self._beat(now)
            except Exception:
                log.exception("session heart step failed")
            self._stepped.set()
            idle = not self.governor.driving and not self.lease.view(now).live
            if idle:  # the link's next change of level comes by the rest timer, which statuses move on
                self._watch_level()
                wake = now + HEART_IDLE_SLEEP
            else:
                self._unwatch_level()
                wake = min(self.governor.next_wakeup(now), self.health.next_change(now))
            delay = min(HEART_IDLE_SLEEP if idle else HEART_MAX_SLEEP, max(0.0, wake - self.ctx.clock()))
            due = self.ctx.clock() + delay
            with contextlib.suppress(TimeoutError):
                async with asyncio.timeout(delay):
                    await self._kick.wait()
            if not self._kick.is_set():  # woke by its timer: how late this machine ran it
                self.health.note_wake(self.ctx.clock() - due)

    async def _judged_now(self) -> float:
        """The time to judge the link at — after taking in any status that has arrived unread.

        The link is judged stale on no status *arriving*, not on this thread reading none: on a
        loaded laptop the loop may run 150–300 ms late, and the status that came meanwhile sits in
        the socket (``AriaClient.catch_up``). A silent link has nothing unread and costs nothing."""
        now = self.ctx.clock()
        client = self.ctx.client
        if client is None or not self.health.running or self.health.level(now) is LinkLevel.OK:
            return now
        return self.ctx.clock() if await client.catch_up() else now

    def _beat(self, now: float) -> None:
        if self.guardian.poll():
            # It stopped the robot (we were frozen, or too slow): no drive resumes without a fresh press.
            self.lease.end(EndReason.STOPPED)
        client = self.ctx.client
        if self.busy() and client is not None:
            self.health.note_traffic(client.last_packet_at)  # map bytes keep the link alive
        else:
            self.health.traffic_done()
        level = self.health.level(now)
        link_ok = level is LinkLevel.OK and client is not None and client.connected
        if self._unguarded(now):
            link_ok = False  # nothing is sent until the guardian is armed (a drive going was ended above)
        for action in self.governor.step(
            now, link_ok, lambda: f"{self.health.cause(now)}. {self.health.advice()}"
        ):
            if isinstance(action, SendRatios):
                r = action.ratios
                self.guardian.arm()  # before the first ratioDrive of a drive
                self.send(RatioDrive(r.trans, r.rot, r.throttle, r.lat or None))
            elif isinstance(action, SendStop):
                self.send_stop(f"lease {action.reason.value}" + (f": {action.why}" if action.why else ""))
        self.publish_health(now)
        target = self.ctx.target
        if level is LinkLevel.LOST and client is not None and target is not None and target.auto_reconnect:
            where = f"{target.host}:{target.port}"
            if self.health.requests_unanswered:
                why = f"{where} answered none of the last {self.health.ping_failures} pings"
            else:
                why = f"no status from {where} for {self.health.lost_after:g} s"
            self.on_lost(ServerClosed(why))

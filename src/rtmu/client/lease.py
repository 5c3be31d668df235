"""The drive lease: the robot moves only while the UI keeps saying so.

Threads: the UI thread *grants* a lease when a drive key goes down and *renews*
it from its own timer while the key is held; the network thread reads it on its
own timer (:class:`DriveGovernor`) and sends ``ratioDrive`` only while the lease
is fresher than :data:`LEASE_TTL`. A frozen UI stops renewing, the lease lapses,
and the network side sends a stop at once — the network keeps its timing while
the UI is busy, yet a busy UI can never keep the robot moving.

A lapsed or revoked lease is dead for good: renewing it does nothing. Only a new
:meth:`DriveLease.grant` (a fresh key press) starts motion again — which is also
how "after a reconnect the robot stays still until a fresh key press" is kept.

The governor is pure logic over an injected clock (no asyncio), so the hold, the
lapse and the stale-link stop are tested with a fake clock.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import Enum

from ..base.i18n import N_, Said
from ..base.units import Quantity

LEASE_TTL = 0.3
"""Seconds a grant or renewal keeps the robot driving (the issue's ~300 ms)."""
RESEND_PERIOD = 0.1
"""ratioDrive is resent at 10 Hz while the lease is live (ARIA's watchdog stops after 2 s without)."""


@dataclass(frozen=True, slots=True)
class DriveRatios:
    """One ``ratioDrive``: trans/rot/lat in −100…100 % (rot positive = left), throttle 0…100 %."""

    trans: float = 0.0
    rot: float = 0.0
    throttle: float = 100.0
    lat: float = 0.0

    @property
    def moving(self) -> bool:
        return (self.trans != 0 or self.rot != 0 or self.lat != 0) and self.throttle > 0


STOPPED = DriveRatios(0.0, 0.0, 0.0)


class EndReason(Enum):
    RELEASED = "released"
    """The operator let go of the keys."""
    LAPSED = "lapsed"
    """Not renewed in time: the UI is frozen or too busy."""
    STOPPED = "stopped"
    """Explicit stop (stop key, focus loss)."""
    LINK = "link"
    """The link went stale or was lost."""
    DISCONNECTED = "disconnected"


@dataclass(frozen=True, slots=True)
class LeaseEvent:
    """What happened to the lease, for a flight recorder: ``grant``, ``change`` or ``end`` (with why)."""

    event: str
    generation: int
    ratios: DriveRatios
    reason: EndReason | None = None


@dataclass(frozen=True, slots=True)
class LeaseView:
    """A consistent snapshot of the lease for the network side."""

    generation: int
    ratios: DriveRatios
    live: bool
    expires_at: float
    ended: EndReason | None


class DriveLease:
    """Thread-safe lease shared by the UI thread (grant/renew/change/release) and the network thread.

    ``on_change`` (set by the runner) is called after grant, change, release and
    revoke from the calling thread; the runner uses it to wake the network loop
    so a key press goes out at once instead of at the next 100 ms tick.
    """

    def __init__(self, *, ttl: float = LEASE_TTL, clock: Callable[[], float] = time.monotonic) -> None:
        self.ttl = ttl
        self.clock = clock
        self.on_change: Callable[[], None] | None = None
        self.on_event: Callable[[LeaseEvent], None] | None = None
        """Optional tap (a recorder) on grants, changes and ends; called on the calling thread."""
        self.on_renew: Callable[[], None] | None = None
        """Called on the renewing thread after each grant, renewal or change (the lease keeper's account)."""
        self.before_lapse: Callable[[float], None] | None = None
        """Called (outside the lock) when a lease not ended is found past its time, before anyone
        acts on it: the :class:`~rtmu.client.lease_keeper.LeaseKeeper` catches up first — its own
        thread may have waited behind a starved renewer too."""
        self._lock = threading.Lock()
        self._generation = 0
        self._ratios = STOPPED
        self._renewed_at = float("-inf")
        self._real_renewal: tuple[float, int] | None = None
        """(time, thread id) of the last grant, renewal or change by the UI side (not an extension)."""
        self._ended: EndReason | None = EndReason.RELEASED
        self._why = ""

    # -- UI side -----------------------------------------------------------------------------
    def grant(self, ratios: DriveRatios) -> int:
        """Start a new lease (a fresh key press); returns its generation."""
        with self._lock:
            self._generation += 1
            self._ratios = ratios
            self._renewed_at = self.clock()
            self._real_renewal = (self._renewed_at, threading.get_native_id())
            self._ended = None
            self._why = ""
            generation = self._generation
        self._renewed()
        self._event(LeaseEvent("grant", generation, ratios))
        self._changed()
        return generation

    def _catch_up(self) -> None:
        hook = self.before_lapse
        if hook is None:
            return
        with self._lock:
            now = self.clock()
            expired = self._ended is None and not self._live(now)
        if expired:
            hook(now)

    def renew(self) -> bool:
        """Keep a live lease alive; False when it has lapsed or was ended (it stays dead)."""
        self._catch_up()
        with self._lock:
            now = self.clock()
            if not self._live(now):
                return False
            self._renewed_at = max(self._renewed_at, now)
            self._real_renewal = (now, threading.get_native_id())
        self._renewed()
        return True

    def _renewed(self) -> None:
        hook = self.on_renew
        if hook is not None:
            hook()

    def extend(self, at: float) -> bool:
        """Move the renewal forward to ``at`` (never back, never past now): the
        :class:`~rtmu.client.lease_keeper.LeaseKeeper`'s credit for a renewing thread that only waited
        for a CPU. Only a lease nobody has ended, and only so far that it is live at ``at``'s credit:
        one already ended (released, stopped, or found lapsed and ended) stays dead. True if it moved."""
        with self._lock:
            now = self.clock()
            at = min(at, now)
            if self._ended is not None or at <= self._renewed_at or now - at > self.ttl:
                return False
            self._renewed_at = at
            return True

    def last_renewal(self) -> tuple[float, int] | None:
        """(time, native thread id) of the UI side's last grant, renewal or change while the lease lives."""
        with self._lock:
            return self._real_renewal if self._ended is None else None

    def change(self, ratios: DriveRatios) -> bool:
        """New ratios for the live lease (one of two held keys released, speed step); renews it."""
        self._catch_up()
        with self._lock:
            now = self.clock()
            if not self._live(now):
                return False
            self._ratios = ratios
            self._renewed_at = max(self._renewed_at, now)
            self._real_renewal = (now, threading.get_native_id())
            generation = self._generation
        self._renewed()
        self._event(LeaseEvent("change", generation, ratios))
        self._changed()
        return True

    def release(self) -> None:
        """The operator let go: the network side sends zero ratios and ``stop``."""
        self.end(EndReason.RELEASED)

    def end(self, reason: EndReason, generation: int | None = None, why: str = "") -> bool:
        """End the lease (if ``generation`` is given, only that one); True if a live lease ended.

        ``why``: the measured cause, in words, where the side that ended it knows one (the network
        side's link health, the lapse's length) — the view says it (:attr:`why`)."""
        with self._lock:
            if generation is not None and generation != self._generation:
                return False
            was_live = self._ended is None
            if was_live:
                self._ended = reason
                self._why = why
            ended, ratios = self._generation, self._ratios
        if was_live:
            self._event(LeaseEvent("end", ended, ratios, reason))
            self._changed()
        return was_live

    # -- both sides --------------------------------------------------------------------------
    def view(self, now: float | None = None) -> LeaseView:
        self._catch_up()
        with self._lock:
            now = self.clock() if now is None else now
            return LeaseView(
                self._generation, self._ratios, self._live(now), self._renewed_at + self.ttl, self._ended
            )

    @property
    def ended(self) -> EndReason | None:
        """Why the current lease ended; None while it has not been ended explicitly."""
        with self._lock:
            return self._ended

    @property
    def why(self) -> str:
        """The measured cause given when the current lease ended ("" if none was given)."""
        with self._lock:
            return self._why

    def _live(self, now: float) -> bool:
        return self._ended is None and now - self._renewed_at <= self.ttl

    def _event(self, event: LeaseEvent) -> None:
        tap = self.on_event
        if tap is not None:
            tap(event)

    def _changed(self) -> None:
        hook = self.on_change
        if hook is not None:
            hook()


@dataclass(frozen=True, slots=True)
class SendRatios:
    ratios: DriveRatios


@dataclass(frozen=True, slots=True)
class SendStop:
    """Zero ratios then ``stop``: what every end of motion sends."""

    reason: EndReason
    why: str = field(default="", compare=False)
    """The measured cause where the governor ended the lease itself (a bad link, a lapse)."""


DriveAction = SendRatios | SendStop


class DriveGovernor:
    """Network-side decisions: what to send now, and when to look again. Pure; feed it a clock.

    ``step(now, link_ok)`` returns the packets to send:

    * lease live and link OK → ``SendRatios`` at once on a new grant or new ratios,
      then every :data:`RESEND_PERIOD`;
    * the lease ended, lapsed, or the link is not OK while we were driving →
      one ``SendStop``; a lapse or a bad link also ends the lease so it cannot
      come back without a fresh grant.
    """

    def __init__(self, lease: DriveLease, *, period: float = RESEND_PERIOD) -> None:
        self.lease = lease
        self.period = period
        self._driving_generation: int | None = None
        self._sent_ratios: DriveRatios | None = None
        self._last_sent = float("-inf")

    @property
    def driving(self) -> bool:
        return self._driving_generation is not None

    def step(
        self, now: float, link_ok: bool = True, link_why: Callable[[], str] | None = None
    ) -> list[DriveAction]:
        view = self.lease.view(now)
        if view.live and link_ok:
            fresh = self._driving_generation != view.generation or self._sent_ratios != view.ratios
            if fresh or now - self._last_sent >= self.period - 1e-9:
                self._driving_generation = view.generation
                self._sent_ratios = view.ratios
                self._last_sent = now
                return [SendRatios(view.ratios)]
            return []
        if self._driving_generation is None:
            return []
        why = ""
        if view.ended is not None:
            reason = view.ended
        elif not link_ok and view.live:
            reason = EndReason.LINK
            why = link_why() if link_why is not None else ""
        else:
            reason = EndReason.LAPSED
            silent = now - (view.expires_at - self.lease.ttl)
            why = Said(N_("the drive was not renewed for {silent}"), silent=Quantity(silent, "s", 2))
        if not self.lease.end(reason, self._driving_generation, why):
            why = self.lease.why if view.ended is not None else why
        self._driving_generation = None
        self._sent_ratios = None
        return [SendStop(reason, why)]

    def next_wakeup(self, now: float) -> float:
        """When ``step`` must run again at the latest (a resend or the lease's expiry)."""
        view = self.lease.view(now)
        if self._driving_generation is None or not view.live:
            return now + self.period
        return min(self._last_sent + self.period, view.expires_at + 1e-4)

    def reset(self) -> None:
        """Forget that we were driving (the connection is gone; nothing more to stop)."""
        self._driving_generation = None
        self._sent_ratios = None
        self._last_sent = float("-inf")

"""Link health, always measured: status age, round-trip time, dropped packets → OK / STALE / LOST.

ArNetworking has no keep-alive (protocol §2.12, §3.8): a dead Wi-Fi link looks
exactly like a quiet robot unless we watch the status stream we subscribed to.
So the status subscription *is* the heartbeat:

* **stale** — no status for longer than this link's learned limit
  (:mod:`~rtmu.base.link_timing`: at least :data:`STALE_INTERVALS` update intervals — 300 ms at
  10 Hz — and at most :data:`~rtmu.base.link_timing.STATUS_CEILING`): driving stops, the
  operator sees it, with the measured cause (:meth:`HealthMonitor.cause`);
* **lost**  — no status for :data:`LOST_AFTER` s: the connection is treated as
  gone (the session reconnects if the profile asks for it).

Round-trip time comes from a cheap request-once every second (the first of
:data:`PING_CANDIDATES` the server offers); how long one may take is learned the same way
(:meth:`HealthMonitor.ping_deadline`). A ping that gets no answer matters as
much as a missing status: a server that keeps *sending* status but has stopped
*reading* (or answering) would never hear our ``stop``. So an unanswered ping makes
the RTT unknown and the link at least **stale** (driving stops); after
:data:`PING_FAILURES_LOST` in a row the link is **lost**. Pure logic over an
injected clock.
"""

from __future__ import annotations

from collections.abc import Callable

from ..base.i18n import N_, Said
from ..base.link_timing import STATUS_CEILING, Deadline, Timing, WakeLateness, ceiling_for
from ..base.units import Quantity
from ..protocol.decoder import DropStats
from ..values.state import LinkHealth, LinkLevel

STALE_INTERVALS = 3
LOST_AFTER = 2.0
PING_INTERVAL = 1.0
PING_FLOOR = 0.4
"""A ping is given at least this long, however steady the link: a Wi-Fi stall of 300 ms may hold its
answer (the busy profile's longest)."""
PING_CEILING = 0.5
"""…and at most this long: a round trip over 0.5 s is no link to drive on — a stop sent now would
reach the robot too late — so the ping fails and driving stops ("no ping")."""
PING_FAILURES_LOST = 3
"""Unanswered pings in a row after which the link counts as lost (a server that stopped reading)."""
PING_CANDIDATES = ("ackCommTcp", "getSafeDrive", "getMapName", "batteryInfo", "physicalInfo", "getModeInfo")
"""Data with a small single reply and no side effect, in order of preference."""


class HealthMonitor:
    def __init__(
        self,
        status_interval: float = 0.1,
        *,
        stale_intervals: int = STALE_INTERVALS,
        lost_after: float = LOST_AFTER,
        ping_failures_lost: int = PING_FAILURES_LOST,
        stale_ceiling: float = STATUS_CEILING,
        ping_floor: float = PING_FLOOR,
        ping_ceiling: float | None = None,
    ) -> None:
        self.status_interval = status_interval
        floor = stale_intervals * status_interval
        self.status_timing = Deadline(status_interval, floor, max(floor, stale_ceiling))
        """Gaps between status packets → the stale limit (``base.link_timing``)."""
        self.wake_lateness = WakeLateness()
        """How late the loop that stops the robot wakes (:meth:`note_wake`): lowers the ceiling."""
        self.lost_after = max(lost_after, self.status_timing.ceiling)
        ping_ceiling = PING_CEILING if ping_ceiling is None else ping_ceiling
        self.ping_timing = Deadline(0.0, min(ping_floor, ping_ceiling), ping_ceiling, fixed=ping_ceiling)
        """Round trips → how long a ping may go unanswered."""
        self.where = "the server"
        self.undecided: Callable[[], bool] = _never
        """True while the decoder holds a header with valid packets behind it (see :meth:`bind`):
        the stream is alive and about to be delivered, so the stale limit is its ceiling meanwhile."""
        self.last_packet_at: Callable[[], float | None] = _unknown
        """When any packet last arrived (see :meth:`bind`): tells a quiet server from a dead link."""
        self.ping_failures_lost = ping_failures_lost
        self._started: float | None = None
        self._last_status: float | None = None
        self.rtt: float | None = None
        self.ping_failures = 0
        """Pings in a row that got no answer (0 after any answered one)."""
        self.bad_payloads = 0
        """Packets that arrived intact but could not be decoded (counted with the decoder's drops)."""
        self._last_traffic: float | None = None

    def bind(
        self, where: str, last_packet_at: Callable[[], float | None], undecided: Callable[[], bool]
    ) -> None:
        """Watch one connection: its name for the words, its packet clock and its decoder."""
        self.where = where
        self.last_packet_at = last_packet_at
        self.undecided = undecided

    @property
    def running(self) -> bool:
        return self._started is not None

    def start(self, now: float) -> None:
        """A connection is up: the status age counts from now until the first status arrives."""
        self._started = now
        self._last_status = None
        self.status_timing.reset(now)
        self.ping_timing.reset(now)
        self.rtt = None
        self.ping_failures = 0
        self.bad_payloads = 0
        self._last_traffic = None

    def stop(self) -> None:
        self._started = None
        self._last_status = None

    def note_status(self, now: float) -> None:
        last = self._last_status
        if last is not None and now >= last:
            self.status_timing.note(now - last, now)
        self._last_status = now

    def note_wake(self, late: float) -> None:
        """The stopping loop woke from its timer ``late`` s after it meant to (0 or less: on time)."""
        self.wake_lateness.note(late)

    def ceiling(self, now: float) -> float:
        """The stale limit's ceiling now: under the promise by the loop's worst recent lateness."""
        timing = self.status_timing
        return ceiling_for(self.wake_lateness.value(), timing.floor, timing.ceiling)

    def stale_limit(self, now: float) -> float:
        """Seconds without status after which the link is stale, now (learned; see ``base.link_timing``)."""
        return self.status_timing.limit(now, undecided=self.undecided(), ceiling=self.ceiling(now))

    def ping_deadline(self, now: float) -> float:
        """How long the next ping may go unanswered before it counts as a failure (learned)."""
        return self.ping_timing.limit(now)

    def timing(self, now: float) -> Timing:
        """What the status stream's timing has learned (for a HUD, ``rtmu doctor``, a stop's words)."""
        return self.status_timing.timing(now, ceiling=self.ceiling(now))

    def note_traffic(self, at: float | None) -> None:
        """Packets arrived at ``at`` (during a map download): the link is alive, if not fresh.

        A server streaming a long map may send no status meanwhile; calling the link
        *lost* then would reconnect and download the map again, for ever. Traffic only
        keeps the link from LOST: STALE still follows the status age, so driving stops.
        """
        if at is not None and (self._last_traffic is None or at > self._last_traffic):
            self._last_traffic = at

    def traffic_done(self) -> None:
        """The download is over: from now on only status (and answered pings) keep the link alive."""
        self._last_traffic = None

    def _traffic_alive(self, now: float) -> bool:
        return self._last_traffic is not None and now - self._last_traffic <= self.lost_after

    def note_rtt(self, seconds: float, now: float | None = None) -> None:
        self.rtt = seconds
        self.ping_failures = 0
        if now is not None:
            self.ping_timing.note(seconds, now)

    def note_ping_timeout(self) -> None:
        """A ping got no answer in time: the RTT is unknown, and the link no better than stale."""
        self.rtt = None
        self.ping_failures += 1

    @property
    def requests_unanswered(self) -> bool:
        """True when the link is lost because pings go unanswered (not because status stopped)."""
        return self.ping_failures >= self.ping_failures_lost

    def status_age(self, now: float) -> float | None:
        if self._started is None:
            return None
        return now - (self._last_status if self._last_status is not None else self._started)

    def level(self, now: float) -> LinkLevel:
        age = self.status_age(now)
        if age is None:
            return LinkLevel.DOWN
        if self.ping_failures >= self.ping_failures_lost and not self._traffic_alive(now):
            return LinkLevel.LOST  # (a map download's bytes may hold our answers up: not lost then)
        if age > self.lost_after and not self._traffic_alive(now):
            return LinkLevel.LOST
        if age > self.stale_limit(now) or self.ping_failures:
            return LinkLevel.STALE
        return LinkLevel.OK

    def next_change(self, now: float) -> float:
        """The time at which :meth:`level` would get worse if no status arrives."""
        age = self.status_age(now)
        if age is None:
            return float("inf")
        since = now - age
        for limit in (self.stale_limit(now), self.lost_after):
            if age <= limit:
                return since + limit + 1e-4
        if self._last_traffic is not None and self._traffic_alive(now):
            return self._last_traffic + self.lost_after + 1e-4
        return float("inf")

    def snapshot(self, now: float, drops: DropStats | None = None) -> LinkHealth:
        drops = drops or DropStats()
        rtt_ms = None if self.rtt is None else round(self.rtt * 1000.0, 1)
        level = self.level(now)
        timing = self.timing(now)
        return LinkHealth(
            level=level,
            rtt_ms=rtt_ms,
            dropped=drops.dropped + self.bad_payloads,
            garbage_bytes=drops.garbage_bytes,
            status_age=self.status_age(now),
            ping_failures=self.ping_failures,
            stale_limit=round(self.stale_limit(now), 2),
            jitter_ms=round(timing.jitter * 200.0) * 5.0,
            cause=""
            if level in (LinkLevel.OK, LinkLevel.DOWN)
            else Said("{cause}. {advice}", cause=self.cause(now), advice=self.advice()),
        )

    def cause(self, now: float) -> str:
        """Why the link is not OK now, measured — one sentence for a notice or stderr.

        Other data still arriving while status does not means the server, not the link, went quiet.
        """
        where = self.where
        if self.ping_failures:
            return Said(
                N_(
                    "{where} did not answer a ping within {deadline} ({count} in a row): "
                    "it may not hear our commands"
                ),
                where=where,
                deadline=Quantity(self.ping_deadline(now), "s", 2),
                count=self.ping_failures,
            )
        age = self.status_age(now) or 0.0
        last_packet_at = self.last_packet_at()
        if last_packet_at is not None and now - last_packet_at < age / 2:
            what = N_("other data still arrives, so the server itself is slow or stopped sending status")
        else:
            what = N_("nothing at all arrived — Wi-Fi, network or the server")
        return Said(
            N_("no status from {where} for {age} ({timing}): {what}"),
            where=where,
            age=Quantity(age, "s", 2),
            timing=self.timing(now).describe(),
            what=Said(what),
        )

    def advice(self) -> str:
        """What the operator can do about :meth:`cause`."""
        if self.ping_failures:
            return Said(N_("Check the robot's Wi-Fi and that its server still runs, then drive again."))
        return Said(N_("Check the robot's Wi-Fi (signal, roaming between access points), then drive again."))


def _never() -> bool:
    return False


def _unknown() -> float | None:
    return None


def ping_data(offers: object) -> str | None:
    """The data to measure RTT with on this server, or None if it offers none of the candidates."""
    for name in PING_CANDIDATES:
        if name in offers:  # type: ignore[operator]
            return name
    return None

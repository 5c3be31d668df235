"""Link health, always measured: status age, round-trip time, dropped packets → OK / STALE / LOST.

ArNetworking has no keep-alive (protocol §2.12, §3.8): a dead Wi-Fi link looks
exactly like a quiet robot unless we watch the status stream we subscribed to.
So the status subscription *is* the heartbeat:

* **stale** — no status for :data:`STALE_INTERVALS` update intervals (300 ms at
  10 Hz): driving stops, the operator sees it;
* **lost**  — no status for :data:`LOST_AFTER` s: the connection is treated as
  gone (the session reconnects if the profile asks for it).

Round-trip time comes from a cheap request-once every second (the first of
:data:`PING_CANDIDATES` the server offers). A ping that gets no answer matters as
much as a missing status: a server that keeps *sending* status but has stopped
*reading* (or answering) would never hear our ``stop``. So an unanswered ping makes
the RTT unknown and the link at least **stale** (driving stops); after
:data:`PING_FAILURES_LOST` in a row the link is **lost**. Pure logic over an
injected clock.
"""

from __future__ import annotations

from ..protocol.decoder import DropStats
from ..values.state import LinkHealth, LinkLevel

STALE_INTERVALS = 3
LOST_AFTER = 2.0
PING_INTERVAL = 1.0
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
    ) -> None:
        self.status_interval = status_interval
        self.stale_after = stale_intervals * status_interval
        self.lost_after = max(lost_after, self.stale_after)
        self.ping_failures_lost = ping_failures_lost
        self._started: float | None = None
        self._last_status: float | None = None
        self.rtt: float | None = None
        self.ping_failures = 0
        """Pings in a row that got no answer (0 after any answered one)."""
        self.bad_payloads = 0
        """Packets that arrived intact but could not be decoded (counted with the decoder's drops)."""
        self._last_traffic: float | None = None

    @property
    def running(self) -> bool:
        return self._started is not None

    def start(self, now: float) -> None:
        """A connection is up: the status age counts from now until the first status arrives."""
        self._started = now
        self._last_status = None
        self.rtt = None
        self.ping_failures = 0
        self.bad_payloads = 0
        self._last_traffic = None

    def stop(self) -> None:
        self._started = None
        self._last_status = None

    def note_status(self, now: float) -> None:
        self._last_status = now

    def note_traffic(self, at: float | None) -> None:
        """Packets arrived at ``at`` (during a map download): the link is alive, if not fresh.

        A server streaming a long map may send no status meanwhile; calling the link
        *lost* then would reconnect and download the map again, for ever. Traffic only
        keeps the link from LOST: STALE still follows the status age, so driving stops.
        """
        if at is not None and (self._last_traffic is None or at > self._last_traffic):
            self._last_traffic = at

    def _traffic_alive(self, now: float) -> bool:
        return self._last_traffic is not None and now - self._last_traffic <= self.lost_after

    def note_rtt(self, seconds: float) -> None:
        self.rtt = seconds
        self.ping_failures = 0

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
        if self.ping_failures >= self.ping_failures_lost:
            return LinkLevel.LOST
        if age > self.lost_after and not self._traffic_alive(now):
            return LinkLevel.LOST
        if age > self.stale_after or self.ping_failures:
            return LinkLevel.STALE
        return LinkLevel.OK

    def next_change(self, now: float) -> float:
        """The time at which :meth:`level` would get worse if no status arrives."""
        age = self.status_age(now)
        if age is None:
            return float("inf")
        since = now - age
        for limit in (self.stale_after, self.lost_after):
            if age <= limit:
                return since + limit + 1e-4
        if self._last_traffic is not None and self._traffic_alive(now):
            return self._last_traffic + self.lost_after + 1e-4
        return float("inf")

    def snapshot(self, now: float, drops: DropStats | None = None) -> LinkHealth:
        drops = drops or DropStats()
        rtt_ms = None if self.rtt is None else round(self.rtt * 1000.0, 1)
        return LinkHealth(
            level=self.level(now),
            rtt_ms=rtt_ms,
            dropped=drops.dropped + self.bad_payloads,
            garbage_bytes=drops.garbage_bytes,
            status_age=self.status_age(now),
            ping_failures=self.ping_failures,
        )


def ping_data(offers: object) -> str | None:
    """The data to measure RTT with on this server, or None if it offers none of the candidates."""
    for name in PING_CANDIDATES:
        if name in offers:  # type: ignore[operator]
            return name
    return None

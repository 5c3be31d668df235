"""Link health levels from status age, and the reconnect backoff."""

from __future__ import annotations

import random

from rtmu.client.errors import ClientTimeout, LoginRejected, ServerClosed
from rtmu.client.health import HealthMonitor, ping_data
from rtmu.client.reconnect import Backoff, worth_retrying
from rtmu.model.observables import LinkLevel
from rtmu.protocol.decoder import DropStats


def test_levels_follow_the_status_age() -> None:
    h = HealthMonitor(0.1, lost_after=2.0)
    assert h.level(0.0) is LinkLevel.DOWN
    h.start(10.0)
    assert h.level(10.2) is LinkLevel.OK
    assert h.level(10.31) is LinkLevel.STALE  # 3 intervals without status
    h.note_status(10.31)
    assert h.level(10.5) is LinkLevel.OK
    assert h.level(12.32) is LinkLevel.LOST
    assert abs(h.next_change(10.5) - 10.61) < 1e-3
    assert abs(h.next_change(10.7) - 12.31) < 1e-3
    h.stop()
    assert h.level(20.0) is LinkLevel.DOWN


def test_snapshot_counts_drops_and_rounds_rtt() -> None:
    h = HealthMonitor(0.1)
    h.start(0.0)
    h.note_rtt(0.00123456)
    h.bad_payloads = 2
    snap = h.snapshot(0.05, DropStats(bad_checksum=3, garbage_bytes=40))
    assert snap.rtt_ms == 1.2 and snap.dropped == 5 and snap.garbage_bytes == 40
    assert snap.level is LinkLevel.OK
    # The age is not part of equality: a fresh-but-same health costs no redraw.
    assert snap == h.snapshot(0.09, DropStats(bad_checksum=3, garbage_bytes=40))


def test_ping_prefers_cheap_data() -> None:
    assert ping_data({"getMapName", "getSafeDrive"}) == "getSafeDrive"
    assert ping_data({"stop"}) is None


def test_backoff_grows_caps_and_resets() -> None:
    b = Backoff(initial=0.5, factor=2, maximum=4, jitter=0.0, rng=random.Random(1))
    assert [b.next_delay() for _ in range(6)] == [0.5, 1, 2, 4, 4, 4]
    b.reset()
    assert b.next_delay() == 0.5


def test_backoff_jitter_stays_within_its_spread_and_really_spreads() -> None:
    rng = random.Random(7)
    for attempt, base in enumerate([0.5, 1.0, 2.0, 4.0, 8.0, 10.0, 10.0]):
        delays = []
        for _ in range(500):
            b = Backoff(initial=0.5, factor=2, maximum=10, jitter=0.2, rng=rng, attempt=attempt)
            delays.append(b.next_delay())
            assert b.attempt == attempt + 1
        assert all(base * 0.8 <= d <= base * 1.2 for d in delays)
        assert min(delays) < base * 0.9 and max(delays) > base * 1.1  # spread over the range
        assert len(set(delays)) > 400  # not one value repeated


def test_only_healable_failures_are_retried() -> None:
    assert worth_retrying(ServerClosed("x")) and worth_retrying(ClientTimeout("x"))
    assert not worth_retrying(LoginRejected(1))


def test_unanswered_pings_spoil_the_link_even_while_status_flows() -> None:
    h = HealthMonitor(0.1, lost_after=2.0, ping_failures_lost=3)
    h.start(0.0)
    h.note_rtt(0.002)
    assert h.level(0.05) is LinkLevel.OK
    h.note_ping_timeout()
    h.note_status(0.1)  # the status stream is fine…
    assert h.rtt is None and h.level(0.1) is LinkLevel.STALE  # …but our requests are not heard
    assert h.snapshot(0.1).rtt_ms is None and h.snapshot(0.1).ping_failures == 1
    h.note_ping_timeout()
    h.note_ping_timeout()
    assert h.level(0.1) is LinkLevel.LOST and h.requests_unanswered
    h.note_rtt(0.003)  # one answer is enough
    assert h.level(0.1) is LinkLevel.OK and not h.requests_unanswered


def test_traffic_during_a_download_keeps_the_link_from_lost_but_not_from_stale() -> None:
    h = HealthMonitor(0.1, lost_after=2.0)
    h.start(10.0)
    h.note_status(10.0)
    h.note_traffic(11.9)  # map packets, no status
    assert h.level(12.5) is LinkLevel.STALE  # driving still stops: status is old
    assert abs(h.next_change(12.5) - 13.9) < 1e-3
    assert h.level(13.95) is LinkLevel.LOST  # the traffic stopped too
    h.note_traffic(None)
    h.note_traffic(5.0)  # an older time never moves it back
    assert h.level(13.95) is LinkLevel.LOST
    h.start(20.0)  # a new connection forgets the old traffic
    assert h.level(22.1) is LinkLevel.LOST

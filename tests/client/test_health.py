"""Link health levels from status age, and the reconnect backoff."""

from __future__ import annotations

import random

import pytest

from rtmu.client.errors import ClientTimeout, LoginRejected, ServerClosed
from rtmu.client.health import HealthMonitor, ping_data
from rtmu.client.reconnect import Backoff, worth_retrying
from rtmu.model.observables import LinkLevel
from rtmu.protocol.decoder import DropStats


def steady_status(h: HealthMonitor, start: float, seconds: float, interval: float = 0.1) -> float:
    t = start
    for _ in range(round(seconds / interval)):
        t += interval
        h.note_status(t)
    return t


def test_levels_follow_the_status_age() -> None:
    h = HealthMonitor(0.1, lost_after=2.0)
    assert h.level(0.0) is LinkLevel.DOWN
    h.start(10.0)
    assert h.level(10.2) is LinkLevel.OK
    assert h.level(10.44) is LinkLevel.OK  # a new link starts at the ceiling…
    assert h.level(10.46) is LinkLevel.STALE
    t = steady_status(h, 10.0, 180.0)  # …and a steady one comes down to 3 intervals
    assert h.stale_limit(t) == pytest.approx(0.3)
    assert h.level(t + 0.29) is LinkLevel.OK
    assert h.level(t + 0.31) is LinkLevel.STALE
    h.note_status(t + 0.31)
    t += 0.31
    assert h.level(t + 0.2) is LinkLevel.OK
    assert h.level(t + 2.02) is LinkLevel.LOST
    assert h.next_change(t + 0.1) == pytest.approx(t + h.stale_limit(t + 0.1), abs=1e-3)
    assert h.next_change(t + 0.7) == pytest.approx(t + 2.0, abs=1e-3)
    h.stop()
    assert h.level(t + 20.0) is LinkLevel.DOWN


def test_a_stale_verdict_says_its_measured_cause() -> None:
    h = HealthMonitor(0.1, lost_after=2.0)
    h.start(0.0)
    last_packet: list[float | None] = [None]
    h.bind("robot:7272", lambda: last_packet[0], lambda: False)
    t = steady_status(h, 0.0, 180.0)
    last_packet[0] = t
    snap = h.snapshot(t + 0.35)
    assert snap.level is LinkLevel.STALE and snap.stale_limit == 0.3
    assert snap.cause == (
        "no status from robot:7272 for 0.35 s (learned jitter 0 ms, limit 0.30 s): nothing at all "
        "arrived — Wi-Fi, network or the server. Check the robot's Wi-Fi (signal, roaming between "
        "access points), then drive again."
    )
    last_packet[0] = t + 0.3  # sonar still comes: the server, not the link, went quiet
    assert "the server itself is slow" in h.cause(t + 0.35)
    assert h.snapshot(t + 0.1).cause == ""  # nothing to explain while OK


def test_an_undecided_decoder_holds_the_verdict_until_the_ceiling() -> None:
    h = HealthMonitor(0.1, lost_after=2.0)
    h.start(0.0)
    undecided = [False]
    h.bind("robot:7272", lambda: None, lambda: undecided[0])
    t = steady_status(h, 0.0, 180.0)
    undecided[0] = True  # a fake header waits, valid packets pile up behind it
    assert h.level(t + 0.35) is LinkLevel.OK
    assert h.next_change(t + 0.35) == pytest.approx(t + 0.45, abs=1e-3)
    assert h.level(t + 0.46) is LinkLevel.STALE  # never beyond the ceiling
    undecided[0] = False
    assert h.level(t + 0.35) is LinkLevel.STALE


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


def test_a_machine_that_wakes_us_late_gets_a_lower_ceiling_so_the_promise_holds() -> None:
    """The stop must be on the wire within 0.5 s of the last status: when the loop that sends it
    wakes 150 ms late, wake after wake, the limit keeps that from the promise (0.35 s)."""
    h = HealthMonitor(0.05, stale_intervals=4)
    h.start(0.0)
    assert h.stale_limit(0.0) == pytest.approx(0.45)
    for _ in range(60):
        h.note_wake(0.15)
    assert h.stale_limit(0.0) == pytest.approx(0.35, abs=0.005)
    for _ in range(60):
        h.note_wake(0.4)  # never below the floor
    assert h.stale_limit(0.0) == pytest.approx(0.2)
    for _ in range(100):
        h.note_wake(-0.001)  # on time again (a timer may fire a hair early): the room comes back
    assert h.stale_limit(0.0) == pytest.approx(0.45, abs=0.005)


def test_one_scheduling_hiccup_does_not_pin_a_jittery_links_limit_to_its_floor() -> None:
    """Measured cause of false stops (bench_links, load 13–25): one 0.3 s late wake kept the ceiling
    at the floor for half a minute, and the next Wi-Fi stall the link had taught it stopped the robot
    ("learned jitter 301 ms, limit 0.30 s"). A second of on-time wakes later the link has its room
    again — and a link that really goes silent is still stale within the ceiling."""
    h = HealthMonitor(0.1)
    h.start(0.0)
    t = 0.0
    for i in range(1, 400):  # 40 s of status with a 0.3 s stall every 3 s: jitter ~0.3 s learned
        t += 0.4 if i % 30 == 0 else 0.1
        h.note_status(t)
        h.note_wake(0.002)
    h.note_wake(0.3)  # the machine ran the loop 0.3 s late, once
    for _ in range(10):  # a second of wakes on time
        h.note_wake(0.002)
    assert h.timing(t).jitter > 0.25
    assert h.level(t + 0.42) is LinkLevel.OK  # a stall like the ones it taught us rides through
    assert h.level(t + 0.46) is LinkLevel.STALE  # a silent link is still stale within the ceiling


def test_unanswered_pings_during_a_download_stop_driving_but_do_not_lose_the_link() -> None:
    """A big map on a slow link holds our pings' answers behind its bytes: driving stops (STALE),
    but the link is not called lost — that would reconnect and download the map again, for ever."""
    h = HealthMonitor(0.1, lost_after=2.0)
    h.start(0.0)
    for _ in range(3):
        h.note_ping_timeout()
    h.note_status(1.0)
    h.note_traffic(1.0)
    assert h.level(1.1) is LinkLevel.STALE
    h.traffic_done()
    assert h.level(1.1) is LinkLevel.LOST and h.requests_unanswered

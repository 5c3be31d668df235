"""The drive lease and the network-side governor, on a fake clock: hold, resend, lapse, stale link."""

from __future__ import annotations

import threading

from rtmu.client.lease import DriveGovernor, DriveLease, DriveRatios, EndReason, SendRatios, SendStop

from .fakeclock import FakeClock

FWD = DriveRatios(100, 0, 50)


def make() -> tuple[FakeClock, DriveLease, DriveGovernor]:
    clock = FakeClock()
    lease = DriveLease(clock=clock)
    return clock, lease, DriveGovernor(lease)


def test_nothing_is_sent_without_a_lease() -> None:
    clock, lease, gov = make()
    assert gov.step(clock()) == []
    assert lease.renew() is False  # nothing to renew


def test_grant_sends_at_once_then_every_100ms_while_renewed() -> None:
    clock, lease, gov = make()
    lease.grant(FWD)
    assert gov.step(clock()) == [SendRatios(FWD)]
    assert gov.step(clock()) == []  # no duplicate in the same instant
    sent = 0
    for _ in range(30):  # 3 s of holding, renewed at 10 Hz by the UI
        clock.advance(0.05)
        assert lease.renew()
        sent += len(gov.step(clock()))
        clock.advance(0.05)
        sent += len(gov.step(clock()))
    assert sent == 30
    assert gov.driving


def test_changed_ratios_go_out_immediately() -> None:
    clock, lease, gov = make()
    lease.grant(FWD)
    gov.step(clock())
    clock.advance(0.01)
    curve = DriveRatios(100, 50, 50)
    assert lease.change(curve)
    assert gov.step(clock()) == [SendRatios(curve)]


def test_release_sends_one_stop() -> None:
    clock, lease, gov = make()
    lease.grant(FWD)
    gov.step(clock())
    lease.release()
    assert gov.step(clock()) == [SendStop(EndReason.RELEASED)]
    assert gov.step(clock() + 1) == []
    assert not gov.driving


def test_a_frozen_ui_lets_the_lease_lapse_and_the_robot_stops_within_300ms() -> None:
    clock, lease, gov = make()
    lease.grant(FWD)
    gov.step(clock())
    # The UI freezes: no more renewals. The governor wakes itself at the expiry.
    wake = gov.next_wakeup(clock())
    clock.advance(0.1)
    assert gov.step(clock()) == [SendRatios(FWD)]
    clock.advance(0.1)
    assert gov.step(clock()) == [SendRatios(FWD)]
    expiry = lease.view().expires_at
    assert abs(expiry - (1000.0 + 0.3)) < 1e-9
    clock.now = expiry + 0.001
    assert gov.step(clock()) == [SendStop(EndReason.LAPSED)]
    assert wake <= 1000.0 + 0.1 + 1e-6
    # The UI thaws and renews: too late, the lease stays dead until a fresh grant.
    assert lease.renew() is False
    assert lease.change(FWD) is False
    assert gov.step(clock()) == []
    lease.grant(FWD)
    assert gov.step(clock()) == [SendRatios(FWD)]


def test_next_wakeup_is_the_lease_expiry_when_that_comes_first() -> None:
    clock, lease, gov = make()
    lease.ttl = 0.05
    lease.grant(FWD)
    gov.step(clock())
    assert abs(gov.next_wakeup(clock()) - (clock() + 0.05)) < 1e-3


def test_stale_link_stops_and_the_lease_does_not_come_back() -> None:
    clock, lease, gov = make()
    lease.grant(FWD)
    gov.step(clock())
    clock.advance(0.05)
    lease.renew()
    assert gov.step(clock(), link_ok=False) == [SendStop(EndReason.LINK)]
    assert lease.ended is EndReason.LINK
    clock.advance(0.05)
    assert lease.renew() is False
    assert gov.step(clock(), link_ok=True) == []


def test_end_only_ends_the_named_generation() -> None:
    _clock, lease, _gov = make()
    first = lease.grant(FWD)
    lease.release()
    second = lease.grant(FWD)
    assert second != first
    assert lease.end(EndReason.LAPSED, first) is False
    assert lease.view().live


def test_on_change_is_called_for_grant_change_and_end_not_for_renew() -> None:
    _clock, lease, _gov = make()
    calls: list[str] = []
    lease.on_change = lambda: calls.append("x")
    lease.grant(FWD)
    lease.renew()
    lease.change(DriveRatios(0, 100, 50))
    lease.release()
    lease.release()  # already ended: no second call
    assert len(calls) == 3


def test_renewals_from_another_thread_are_safe() -> None:
    _clock, lease, _gov = make()
    lease.grant(FWD)
    stop = threading.Event()

    def renew() -> None:
        while not stop.is_set():
            lease.renew()

    t = threading.Thread(target=renew)
    t.start()
    try:
        for _ in range(2000):
            view = lease.view()
            assert view.live and view.ratios == FWD
    finally:
        stop.set()
        t.join()


def test_every_stop_the_governor_decides_carries_its_measured_cause() -> None:
    clock, lease, gov = make()
    lease.grant(FWD)
    gov.step(clock())
    clock.advance(0.34)  # not renewed: the UI froze
    [stop] = gov.step(clock())
    assert stop == SendStop(EndReason.LAPSED)
    assert stop.why == "the drive was not renewed for 0.34 s"
    assert lease.why == stop.why  # the view says the same words
    lease.grant(FWD)
    gov.step(clock())
    assert lease.why == ""  # a new lease forgets the old cause
    [stop] = gov.step(clock(), link_ok=False, link_why=lambda: "no status for 0.46 s")
    assert stop.reason is EndReason.LINK and stop.why == lease.why == "no status for 0.46 s"
    lease.grant(FWD)
    gov.step(clock())
    lease.release()
    [stop] = gov.step(clock(), link_ok=False, link_why=lambda: "not asked")
    assert stop.reason is EndReason.RELEASED and stop.why == ""  # the operator's own act: no cause

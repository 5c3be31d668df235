"""The learned stale limit (``base.link_timing``): floor on a steady link, above a jittery link's
stalls, never above the ceiling the safety promise allows — on made-up arrival times, no clock."""

from __future__ import annotations

import random

import pytest

from rtmu.base import link_timing
from rtmu.base.link_timing import JITTER_MEMORY, STATUS_CEILING, Deadline

FLOOR = 0.2  # rtmu drive: 4 × 50 ms


def steady(d: Deadline, start: float, seconds: float, interval: float = 0.05) -> float:
    """Feed a perfectly regular stream; returns the time of its last arrival."""
    t = start
    for _ in range(round(seconds / interval)):
        t += interval
        d.note(interval, t)
    return t


def test_a_new_link_starts_at_the_ceiling_and_a_steady_one_comes_down_to_the_floor() -> None:
    d = Deadline(0.05, FLOOR, STATUS_CEILING)
    assert d.limit(0.0) == STATUS_CEILING  # nothing known yet: TCP's conservative start
    assert d.timing(0.0).learning
    t = steady(d, 0.0, 5.0)
    assert FLOOR < d.limit(t) < STATUS_CEILING  # coming down
    t = steady(d, t, 180.0)
    assert d.limit(t) == pytest.approx(FLOOR)
    assert not d.timing(t).learning and d.timing(t).jitter < 0.001


def test_a_stall_is_remembered_long_enough_for_the_next_one() -> None:
    d = Deadline(0.05, FLOOR, STATUS_CEILING)
    t = steady(d, 0.0, 180.0)
    t += 0.05 + 0.150  # a 150 ms Wi-Fi stall: the next status is that late
    d.note(0.2, t)
    assert d.timing(t).jitter == pytest.approx(0.15, abs=0.01)
    for _ in range(20):
        d.note(0.0, t)  # the held packets arrive in a burst
    assert d.limit(t) > 0.35  # the next stall, even twice as long, is not a fault
    t2 = steady(d, t, 30.0)  # a quiet half-minute later (good Wi-Fi stalls every ~10 s)
    assert d.limit(t2) > 0.05 + 0.3  # a stall twice as long still passes
    late = steady(d, t2, JITTER_MEMORY * 6)  # …and a link that has calmed down gets fast again
    assert d.limit(late) == pytest.approx(FLOOR, abs=0.01)


@pytest.mark.parametrize("seed", range(5))
def test_never_above_the_ceiling_nor_below_the_floor(seed: int) -> None:
    rng = random.Random(seed)
    d = Deadline(0.05, FLOOR, STATUS_CEILING)
    t = 0.0
    for _ in range(5000):
        gap = rng.choice([0.0, 0.05, 0.05, 0.05, rng.uniform(0, 3.0)])
        t += gap
        d.note(gap, t)
        assert FLOOR <= d.limit(t) <= STATUS_CEILING


def test_a_faults_long_gap_teaches_no_more_than_the_ceiling() -> None:
    d = Deadline(0.05, FLOOR, STATUS_CEILING)
    t = steady(d, 0.0, 60.0)
    t += 30.0  # a partition of half a minute, then the link is back
    d.note(30.0, t)
    assert d.mean < 0.2 and d.timing(t).jitter <= STATUS_CEILING
    assert d.limit(t) == STATUS_CEILING


def test_an_undecided_decoder_gets_the_ceiling_never_more() -> None:
    d = Deadline(0.05, FLOOR, STATUS_CEILING)
    t = steady(d, 0.0, 180.0)
    assert d.limit(t) == pytest.approx(FLOOR)
    assert d.limit(t, undecided=True) == STATUS_CEILING


def test_pings_learn_their_round_trip() -> None:
    d = Deadline(0.0, 0.25, 0.5, fixed=0.5)
    assert d.limit(0.0) == pytest.approx(0.5)
    t = 0.0
    for _ in range(800):  # 200 s of 4 Hz pings answered in 2 ms
        t += 0.25
        d.note(0.002, t)
    assert d.limit(t) == pytest.approx(0.25)
    d.note(0.3, t)  # one answer held up 300 ms by a stall
    assert d.limit(t) == pytest.approx(0.5)


def test_learning_off_keeps_the_old_fixed_thresholds(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(link_timing, "LEARNING", False)
    status = Deadline(0.05, FLOOR, STATUS_CEILING)
    ping = Deadline(0.0, 0.25, 0.5, fixed=0.5)
    t = 0.0
    for _ in range(100):
        t += 0.5
        status.note(0.5, t)
        ping.note(0.4, t)
    assert status.limit(t) == FLOOR and ping.limit(t) == 0.5


def test_the_words_say_what_was_learned() -> None:
    d = Deadline(0.05, FLOOR, STATUS_CEILING)
    assert d.timing(0.0).describe().startswith("jitter so far 0 ms, limit 0.45 s")
    t = steady(d, 0.0, 180.0)
    t += 0.14
    d.note(0.14, t)
    assert d.timing(t).describe() == "learned jitter 90 ms, limit 0.34 s"  # 0.061 + 2 × 0.09 + 0.1


def test_floor_above_ceiling_is_refused() -> None:
    with pytest.raises(ValueError):
        Deadline(0.05, 0.5, 0.4)

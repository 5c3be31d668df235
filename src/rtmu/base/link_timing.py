"""How late may the next status (or a ping's answer) be before the link is declared stale? One rule.

A fixed limit is wrong both ways: 200 ms stops a robot on healthy Wi-Fi, whose 802.11 retries,
background scans and contention hold a stream for 50–300 ms now and then, or on a laptop whose
other programs keep a core busy; 2 s would let a robot drive blind. So each link *learns* what it
normally does, as TCP learns its retransmission timeout from the smoothed round trip and its
variance (RFC 6298), and is declared stale at a margin above that — never below a floor (today's
fixed limits, so a clean link stops as fast as ever) and never above a ceiling (what the safety
promise allows: zero ratios and ``stop`` on the wire within 0.5 s of the last status).

:class:`Deadline` learns from samples — the gap between two status packets, or a ping's round
trip — three figures:

* ``mean``: the smoothed sample (RFC 6298's SRTT, gain 1/8);
* ``jitter``: how far samples came *above* the mean lately. Unlike RFC 6298's RTTVAR it rises at
  once to a late sample and then decays slowly (half-life :data:`JITTER_MEMORY`), as Linux's
  ``mdev_max`` does: Wi-Fi stalls are rare events, and a link that stalled 150 ms a minute ago
  will do it again — an average over the last second would have forgotten it;
* a ``prior``: until the link has shown what it does, the limit starts at the ceiling (TCP's
  conservative initial RTO) and comes down with a half-life of :data:`PRIOR_MEMORY`.

``limit = clamp(mean + MARGIN × max(jitter, prior) + PAD, floor, ceiling)``. ``MARGIN`` 2 lets the
next stall be twice the longest one remembered; ``PAD`` covers where in the status period it falls.

The ceiling itself knows the machine: the loop that would send the stop measures how late each of
its timed wake-ups comes (:class:`WakeLateness`: the smoothed lateness and its spread, as the
round trip's), and :func:`ceiling_for` keeps that between the limit and the 0.5 s promise — a
laptop that runs us 150 ms late stops a silent link at 0.35 s, so the stop is still on the wire
within 0.5 s. What the machine *normally* does, not its single worst hiccup: keeping the worst
late wake of the last half minute pinned the limit to its floor for that long after one 0.3 s
scheduling hiccup, and a Wi-Fi stall the link had taught it (jitter 0.2–0.3 s) then stopped the
robot — five of the eight false stops of a 7-minute soak at a load average of 13–25.

While the link is *undecided* — the decoder holds a header whose body has not come but sees
valid packets going on behind it (``PacketDecoder.undecided``) — the limit is the ceiling: the
stream is alive, the decoder will deliver within a few packets, and a stale verdict must not race
it. Pure logic over times passed in; one instance per stream.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

from .i18n import N_, Said
from .units import Quantity

STATUS_PROMISE = 0.5
"""The safety promise: zero ratios and ``stop`` on the wire within this many seconds of the last status."""
STATUS_CEILING = 0.45
"""The status limit's ceiling on a machine that runs us on time: 50 ms under the promise for the
wake-up and the send. On a machine that wakes us late it is lower (:func:`ceiling_for`)."""
WAKE_SPREAD = 2.0
"""The ceiling keeps the stopping loop's smoothed lateness plus this many of its smoothed deviations
under the promise (RFC 6298's ``SRTT + K × RTTVAR``, with the smaller K the wake-ups' own steadiness
allows: they come ten times a second, a round trip's once)."""
DEVIATION_GAIN = 1.0 / 4.0
"""RFC 6298's beta: the weight of a new sample in the smoothed deviation."""
MARGIN = 2.0
PAD = 0.1
"""Added to every learned limit: a stall's lateness is measured from the mean gap, but it may start
just after a status or just before the next one (one status period apart); covers that phase."""
JITTER_MEMORY = 120.0
"""Seconds for the remembered jitter to halve: longer than the gaps between a Wi-Fi's stalls."""
PRIOR_MEMORY = 30.0
"""Seconds for the starting assumption (limit at the ceiling) to halve once samples arrive: long
enough that a link whose first stall comes late (good Wi-Fi stalls about every 10 s) is still
covered when it does."""
GAIN = 1.0 / 8.0
"""RFC 6298's alpha: the weight of a new sample in the smoothed mean."""

FIXED_ENV = "RTMU_LINK_TIMING"
"""``RTMU_LINK_TIMING=fixed`` in the environment: RTMU's limits before it learned them — fixed
status and ping limits here, no run-queue credit for the lease (``lease_keeper``). Benchmarks set
it on a child process (and its guardian inherits it) to measure the difference in the same run."""
LEARNING = os.environ.get(FIXED_ENV, "") != "fixed"
"""False: every :class:`Deadline` built from now on keeps its floor (status) or its ceiling (pings)."""


class WakeLateness:
    """How late the loop that stops the robot wakes from its timers: every timed wake-up is a sample
    (an on-time one is 0), smoothed as RFC 6298 smooths a round trip; :meth:`value` is what the
    status limit's ceiling keeps room for (:func:`ceiling_for`)."""

    def __init__(self) -> None:
        self.mean = 0.0
        self.deviation = 0.0
        self.samples = 0

    def note(self, late: float) -> None:
        late = max(0.0, late)
        self.deviation += DEVIATION_GAIN * (abs(late - self.mean) - self.deviation)
        self.mean += GAIN * (late - self.mean)
        self.samples += 1

    def value(self) -> float:
        return self.mean + WAKE_SPREAD * self.deviation


def ceiling_for(wake_lateness: float, floor: float, ceiling: float = STATUS_CEILING) -> float:
    """The status limit's ceiling on a machine whose stopping loop wakes ``wake_lateness`` s late."""
    return max(floor, min(ceiling, STATUS_PROMISE - wake_lateness))


@dataclass(frozen=True, slots=True)
class Timing:
    """What a :class:`Deadline` has learned, for a HUD, ``rtmu doctor`` and the stop's explanation."""

    limit: float
    """Seconds after which the stream counts as stale (or the ping as unanswered) now."""
    jitter: float
    """Seconds: how late samples came above the mean lately (the remembered envelope)."""
    mean: float
    """The smoothed sample (gap or round trip), seconds."""
    samples: int
    learning: bool
    """True while the starting assumption still sets the limit (too few samples to trust)."""
    fixed: bool = False
    """True when learning is off (:data:`LEARNING`): the limit is the old fixed one."""
    settled: float = 0.0
    """The limit this link's own jitter gives, once the starting assumption has worn off."""

    def describe(self) -> str:
        """``learned jitter 90 ms, limit 0.33 s`` — the words a stop and the HUD use (a :class:`Said`:
        English for logs, the operator's language where shown)."""
        jitter, limit = Quantity(self.jitter * 1000, "ms"), Quantity(self.limit, "s", 2)
        if self.fixed:
            return Said(N_("jitter {jitter}, fixed limit {limit}"), jitter=jitter, limit=limit)
        if self.learning:
            return Said(N_("jitter so far {jitter}, limit {limit}"), jitter=jitter, limit=limit)
        return Said(N_("learned jitter {jitter}, limit {limit}"), jitter=jitter, limit=limit)


class Deadline:
    """Learns one periodic stream (or round trip) and says how long to wait for the next sample."""

    def __init__(
        self,
        expected: float,
        floor: float,
        ceiling: float,
        *,
        fixed: float | None = None,
        learn: bool | None = None,
    ) -> None:
        if not 0.0 < floor <= ceiling:
            raise ValueError(f"need 0 < floor <= ceiling, got {floor!r}, {ceiling!r}")
        self.expected = expected
        """The nominal sample: the subscription's interval, or a first guess at the round trip."""
        self.floor = floor
        self.ceiling = ceiling
        self.fixed = floor if fixed is None else fixed
        """The limit when not learning (:data:`LEARNING` off): the old fixed threshold."""
        self.learn = LEARNING if learn is None else learn
        self.reset(None)

    def reset(self, now: float | None) -> None:
        """A new connection: forget the samples; the limit starts at the ceiling again."""
        self.mean = self.expected
        self.samples = 0
        self._jitter = 0.0
        self._jitter_at = 0.0 if now is None else now
        self._prior = max(0.0, (self.ceiling - self.expected - PAD) / MARGIN)
        self._prior_since: float | None = None

    def note(self, sample: float, now: float) -> None:
        """One sample (a gap between two arrivals, or a round trip) seen at ``now``."""
        if sample < 0.0 or math.isnan(sample):
            return
        if self._prior_since is None:
            self._prior_since = now
        sample = min(sample, self.ceiling)  # a fault's long gap teaches no more than the ceiling
        late = sample - self.mean
        remembered = self._decayed_jitter(now)
        self._jitter = max(remembered, late)
        self._jitter_at = now
        self.mean += GAIN * (sample - self.mean)
        self.samples += 1

    def _decayed_jitter(self, now: float) -> float:
        return self._jitter * 0.5 ** (max(0.0, now - self._jitter_at) / JITTER_MEMORY)

    def _prior_now(self, now: float) -> float:
        if self._prior_since is None:
            return self._prior
        return self._prior * 0.5 ** (max(0.0, now - self._prior_since) / PRIOR_MEMORY)

    def limit(self, now: float, *, undecided: bool = False, ceiling: float | None = None) -> float:
        """Seconds the next sample may take before the stream counts as late (see the module notes);
        ``ceiling``: a lower one for now (:func:`ceiling_for`)."""
        if not self.learn:
            return self.fixed
        top = self.ceiling if ceiling is None else max(self.floor, min(self.ceiling, ceiling))
        if undecided:
            return top
        spread = max(self._decayed_jitter(now), self._prior_now(now))
        return min(top, max(self.floor, self.mean + MARGIN * spread + PAD))

    def timing(self, now: float, *, ceiling: float | None = None) -> Timing:
        jitter = self._decayed_jitter(now)
        limit = self.limit(now, ceiling=ceiling)
        top = self.ceiling if ceiling is None else max(self.floor, min(self.ceiling, ceiling))
        without_prior = min(top, max(self.floor, self.mean + MARGIN * jitter + PAD))
        learning = self.learn and limit - without_prior > 0.005
        return Timing(limit, jitter, self.mean, self.samples, learning, not self.learn, without_prior)

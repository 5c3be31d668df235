"""How fast the robot can go and how far it rolls once told to stop: the numbers behind the near-people
speed cap and the stopping distance drawn ahead of the robot (GTK-free).

Where the numbers come from (facts from ARIA 2.9.1's sources and MobileSim 0.9.8, written here by us):

* An ARIA server that uses ``ArRobotConfig`` lists the robot's limits in its configuration, section
  ``Robot config``: ``TransVelMax`` (mm/s) and ``TransDecel`` (mm/s²), 0 meaning "the robot's own".
  :func:`limits_from_config` reads them when the server offers its configuration.
* Otherwise the limits are assumed from ARIA's P3-DX: ``params/p3dx.p`` gives ``MaxVelocity 2200``
  (the absolute maximum — the safe side for a cap) and leaves ``TransDecel 0``, i.e. the firmware's
  own, which ARCOS ships (and MobileSim emulates) as 300 mm/s².
* ``stop`` (ArServerModeStop → ``ArRobot::stop``: VEL 0, RVEL 0) and zero ``ratioDrive`` ratios
  brake alike, at that TransDecel; only the firmware's ESTOP command overrides it, and ARIA's network
  servers never send that for a client. So a release at 1.5 m/s rolls about 1500²/(2·300) = 3.75 m.
* The reaction before braking (:data:`REACTION_S`) was measured against ARIA's serverDemoMap and
  MobileSim, where zero ratios and ``stop`` both braked at 290–308 mm/s².
* A robot seen going faster than the limits allow (a server that lists none, a robot faster than a
  P3-DX) raises the estimate (:meth:`RobotLimits.seen`): a cap computed from it stays a cap.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ..base.i18n import N_, Said
from ..base.units import Quantity
from ..client.config_feed import ServerConfig

ASSUMED_MAX_MM_S = 2200.0
"""ARIA's ``p3dx.p`` MaxVelocity: the fastest a P3-DX may be told to go."""
ASSUMED_DECEL_MM_S2 = 300.0
"""ARCOS's default TransDecel (``p3dx.p`` keeps the firmware's; MobileSim's Pioneer uses 300 too)."""
REACTION_S = 0.8
"""From the release, as the window shows the robot then, to its braking: measured on ARIA's own server
(serverDemoMap on MobileSim 0.9.8's P3-DX) at about 0.75 s — a 635 mm/s robot rolled 1.16 m while
its speed fell at 295 mm/s² (0.68 m of braking) — from ARIA's 100 ms robot and server cycles, the
firmware's SIP cycle and the status reaching the window; the simulator answers faster (about 0.2 s),
so the strip errs long there, on the safe side."""
SECTION = "Robot config"
MIN_SEEN_MM_S = 50.0
"""Speeds below this say nothing about the robot's maximum (noise, creeping)."""


@dataclass(frozen=True, slots=True)
class RobotLimits:
    """The robot's top speed for a full ``ratioDrive`` (mm/s) and its braking (mm/s²), and their source."""

    max_speed: float = ASSUMED_MAX_MM_S
    decel: float = ASSUMED_DECEL_MM_S2
    source: str = N_("assumed from ARIA's P3-DX")
    """Where the figures come from: English (a :class:`Said` or a marked constant), said with ``words``."""

    def seen(self, speed: float, trans_pct: float, throttle_pct: float) -> RobotLimits:
        """The robot went ``speed`` mm/s at these ratios: a faster maximum than believed raises it."""
        share = abs(trans_pct) / 100.0 * throttle_pct / 100.0
        if abs(speed) < MIN_SEEN_MM_S or share <= 0.0:
            return self
        implied = abs(speed) / share
        if implied <= self.max_speed * 1.05:
            return self
        source = Said(
            N_("seen: {speed} at {share} of full"),
            speed=Quantity(abs(speed), "mm/s"),
            share=Quantity(share * 100, "%"),
        )
        return replace(self, max_speed=implied, source=source)

    def stopping_distance(self, speed: float, reaction: float = REACTION_S) -> float:
        """How far (mm) the robot goes at ``speed`` mm/s once told to stop: reaction, then braking."""
        v = abs(speed)
        return v * reaction + v * v / (2.0 * max(self.decel, 1.0))


def limits_from_config(config: ServerConfig) -> RobotLimits:
    """The server's own ``Robot config`` TransVelMax / TransDecel, the assumed ones where it has none."""
    limits = RobotLimits()
    found = []
    speed = _positive(config, "TransVelMax")
    if speed is not None:
        limits = replace(limits, max_speed=speed)
        found.append("TransVelMax")
    decel = _positive(config, "TransDecel")
    if decel is not None:
        limits = replace(limits, decel=decel)
        found.append("TransDecel")
    if found:
        limits = replace(limits, source=Said(N_("its server's {names}"), names=" and ".join(found)))
    return limits


def _positive(config: ServerConfig, name: str) -> float | None:
    param = config.find(SECTION, name)
    value = param.value if param is not None else None
    if isinstance(value, bool) or not isinstance(value, int | float) or not value > 0:
        return None  # 0 is ARIA's "the robot's own": not a number we know
    return float(value)


def capped_throttle(throttle_pct: float, cap_mm_s: float | None, limits: RobotLimits) -> float:
    """The ``ratioDrive`` throttle (%) that keeps a full-stick drive at or under ``cap_mm_s``.

    ARIA's ratio drive goes ``trans% × throttle% × TransVelMax`` forward (a quarter of it backwards),
    so the throttle is cut to ``100 × cap / TransVelMax`` when that is lower; None: no cap.
    """
    if cap_mm_s is None:
        return throttle_pct
    return min(throttle_pct, 100.0 * max(cap_mm_s, 0.0) / max(limits.max_speed, 1.0))

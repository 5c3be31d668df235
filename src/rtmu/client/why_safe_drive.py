"""Why won't it move? — the safe-drive rule: an obstacle in the robot's path, inside safe drive's reach.

One of :mod:`rtmu.client.why`'s rules (no I/O), apart because it is the one that measures: the
readings in the robot's frame against its footprint and the limiter's distances, as ARIA's
``ArActionDeceleratingLimiter`` measures them — from half the robot's length ahead of (behind) its
centre, within its width plus the side clearance.
"""

from __future__ import annotations

from ..base.i18n import N_, Said, as_said
from ..base.units import Quantity
from .why_values import Cause, Facts, Fix, Footprint, Motion, Obstacle, Reason, SafeDriveLimits


def safe_drive_rule(facts: Facts, motion: Motion | None, navigate: bool) -> list[Reason]:
    """Safe drive holding the robot back: a reading in its path nearer than the limiter allows."""
    if facts.safe_drive is not True or facts.footprint is None or facts.limits is None:
        return []
    if motion is not None and motion.trans == 0:
        return []  # safe drive limits translation only: turning on the spot is not held back
    ways = (True, False) if motion is None else ((motion.trans > 0),)
    out: list[Reason] = []
    for forward in ways:
        hit = nearest(facts.obstacles, facts.footprint, facts.limits, forward)
        if hit is None:
            continue
        obstacle, _ = hit
        limit = facts.limits.front if forward else facts.limits.rear
        way, away = (N_("ahead of"), N_("backwards")) if forward else (N_("behind"), N_("forwards"))
        clear = nearest(facts.obstacles, facts.footprint, facts.limits, not forward) is None
        fix = _safe_off_fix(facts)
        advice = Said(
            N_("drive away from it ({way}{clear}){or_off}"),
            way=Said(away),
            clear=Said(N_(": that way is clear")) if clear else "",
            or_off=Said(N_(", or switch safe drive off (with care: the robot then drives into things)"))
            if fix
            else "",
        )
        out.append(
            Reason(
                Cause.SAFE_DRIVE,
                Said(
                    N_(
                        "safe drive holds the robot back: an obstacle {distance} {way} its centre {side}, "
                        "closer than safe drive allows (half the robot's length + {limit} = {reach})"
                    ),
                    distance=Quantity(abs(obstacle.x), "mm"),
                    way=Said(way),
                    side=_side(obstacle),
                    limit=Quantity(limit, "mm"),
                    reach=Quantity(facts.footprint.reach + limit, "mm"),
                ),
                advice,
                (
                    Said(
                        N_("{sensor}: reading at ({x}, {y}) mm in the robot's frame"),
                        sensor=obstacle.source,
                        x=Quantity(obstacle.x, ""),
                        y=Quantity(obstacle.y, ""),
                    ),
                    Said(N_("limits: {source}"), source=as_said(facts.limits.source)),
                    Said(N_("{request}: on"), request="getSafeDrive"),
                ),
                fix,
            )
        )
        break  # one sentence is enough; the first direction asked about decides
    return out


def _safe_off_fix(facts: Facts) -> Fix | None:
    for name in ("setSafeDrive", "safeRatioDrivingDisable"):
        if name in facts.offers:
            return Fix(
                "safe_drive_off",
                Said(
                    N_("switch safe drive off ({request}); the robot then drives into things"), request=name
                ),
                name,
                True,
            )
    return None


def nearest(
    obstacles: tuple[Obstacle, ...], footprint: Footprint, limits: SafeDriveLimits, forward: bool
) -> tuple[Obstacle, float] | None:
    """The closest reading in the robot's path (its width plus the side clearance) that is nearer
    than the safe-drive distance, with that distance; None when clear. Measured as ARIA's
    ArActionDeceleratingLimiter measures: from half the robot's length ahead of (behind) its centre."""
    half = footprint.width / 2 + limits.side
    best: tuple[Obstacle, float] | None = None
    for o in obstacles:
        if abs(o.y) > half:
            continue
        gap = (o.x if forward else -o.x) - footprint.reach
        if (o.x > 0) != forward or gap >= (limits.front if forward else limits.rear):
            continue
        if best is None or (round(gap), abs(o.y)) < (round(best[1]), abs(best[0].y)):
            best = (o, gap)
    return best


def _side(o: Obstacle) -> Said:
    if abs(o.y) < 50:
        return Said(N_("(straight on)"))
    if o.y > 0:
        return Said(N_("({distance} to the left)"), distance=Quantity(abs(o.y), "mm"))
    return Said(N_("({distance} to the right)"), distance=Quantity(abs(o.y), "mm"))

"""Driving requests (protocol §4.3): ratio drive, safe-drive switch, jog moves.

None of these has a reply except ``getSafeDrive``. Numbers travel as ARIA's
text doubles (``%g``), so only six significant digits survive.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Self

from ..fields import FieldReader, FieldWriter
from .base import Payload, Side, SingleField, SingleFlag, register

RATIO_TRANS_DEAD_ZONE = 10.0
"""ARIA's ratio drive (ArActionRatioInput) ignores a translation ratio within ±10 %…"""
RATIO_ROT_DEAD_ZONE = 5.0
"""…and a rotation ratio under ±5 %: such a ratioDrive moves nothing."""


@register
@dataclass(frozen=True, slots=True)
class RatioDrive(Payload):
    """``ratioDrive`` args: percentages of the robot's maximum speeds.

    ``trans``, ``rot`` and ``lat`` are −100…100 (rot positive = left, lat
    positive = left), ``throttle`` 0…100 scales all three; the server clamps.
    ``lat`` is optional on the wire: ``None`` leaves it out (ARIA reads a
    missing fourth field as 0), which is what ARIA's own client sends.
    The server stops the robot if no ``ratioDrive`` arrives for 2 s while moving.
    """

    DATA_NAME = "ratioDrive"
    SIDE = Side.ARGS

    trans: float
    rot: float
    throttle: float = 100.0
    lat: float | None = None

    @property
    def lat_ratio(self) -> float:
        """The lateral ratio the server uses: 0 when the field was left out."""
        return 0.0 if self.lat is None else self.lat

    @property
    def in_dead_zone(self) -> bool:
        """True when ARIA's dead zones swallow every ratio asked for (and some was asked for)."""
        asked = self.trans != 0 or self.rot != 0
        return asked and abs(self.trans) <= RATIO_TRANS_DEAD_ZONE and abs(self.rot) < RATIO_ROT_DEAD_ZONE

    @property
    def moving(self) -> bool:
        """True if these ratios ask for motion (what ARIA's watchdog checks)."""
        return self.throttle > 0 and (self.trans != 0 or self.rot != 0 or self.lat_ratio != 0)

    def encode(self) -> bytes:
        w = FieldWriter().double(self.trans).double(self.rot).double(self.throttle)
        if self.lat is not None:
            w.double(self.lat)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        trans = r.double("trans ratio")
        rot = r.double("rot ratio")
        throttle = r.double("throttle ratio")
        lat = None if r.at_end() else r.double("lat ratio")
        return cls(trans, rot, throttle, lat)


@register
@dataclass(frozen=True, slots=True)
class SetSafeDrive(SingleFlag):
    """``setSafeDrive`` args: ``False`` turns the obstacle limiters off (group UnsafeMovement)."""

    DATA_NAME = "setSafeDrive"
    SIDE = Side.ARGS
    FIELD_KIND = "ubyte"
    FIELD_LABEL = "safe flag"

    safe: bool


@register
@dataclass(frozen=True, slots=True)
class SafeDrive(SingleFlag):
    """``getSafeDrive`` reply: whether safe driving is on."""

    DATA_NAME = "getSafeDrive"
    SIDE = Side.REPLY
    FIELD_KIND = "ubyte"
    FIELD_LABEL = "safe flag"

    safe: bool


@register
@dataclass(frozen=True, slots=True)
class MoveDist(SingleField):
    """``moveDist`` args (jog mode): drive this many mm, forward positive."""

    DATA_NAME = "moveDist"
    SIDE = Side.ARGS
    FIELD_KIND = "double"
    FIELD_LABEL = "distance"

    distance: float


@register
@dataclass(frozen=True, slots=True)
class TurnByAngle(SingleField):
    """``turnByAngle`` args (jog mode): turn by this many degrees, counter-clockwise positive."""

    DATA_NAME = "turnByAngle"
    SIDE = Side.ARGS
    FIELD_KIND = "double"
    FIELD_LABEL = "angle"

    angle: float


@register
@dataclass(frozen=True, slots=True)
class TurnToHeading(SingleField):
    """``turnToHeading`` args (jog mode): turn to this absolute heading in degrees."""

    DATA_NAME = "turnToHeading"
    SIDE = Side.ARGS
    FIELD_KIND = "double"
    FIELD_LABEL = "heading"

    heading: float

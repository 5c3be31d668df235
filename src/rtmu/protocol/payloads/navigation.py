"""Navigation data of ARNL-class servers (protocol §4.8): goals, poses, home, dock, localization, path.

These are not in ARIA's sources; ARNL registers them. Every layout below was checked against a public
copy of ARNL's own server classes (``ArServerModeGoto``, ``ArServerInfoPath``,
``ArServerInfoLocalization``, ``ArServerHandlerLocalization``, ``ArServerModeDock``), which in two
places differ from ``RemoteRequestAPI.dox`` and §4.8 — the types follow the server's code:

* ``gotoPose``: ARNL reads the optional heading with ``bufToByte4`` (its own data description says
  ``byte4: th`` and its example client sends four bytes); the API page says a 2-byte int. We send
  four bytes; a 2-byte heading is still read, and kept as such (``short_th``).
* ``getLocState``: ARNL sends the score as ``round(score × 1000)`` (0 lost … 1000 perfect), not the
  0–100 the API page gives. :data:`LOC_SCORE_FULL` is that 1000.

``getPath`` is ``byte2`` count then ``byte4 x, byte4 y`` per point (map mm); ARNL leaves out the first
two points of its plan so the line does not start under the robot, and sends ``byte2 0`` when there
is no plan. ``pathPlannerStatus`` and ``goalName`` are one string each.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum
from typing import Final, Self

from ..errors import PayloadError
from ..fields import FieldReader, FieldWriter
from ..packet import MAX_PAYLOAD
from .base import EmptyPayload, Payload, Side, SingleField, checked_count, register

LOC_SCORE_FULL: Final = 1000
"""``getLocState``'s score for a perfect match (ARNL sends ``round(score × 1000)``)."""
PATH_POINT_BYTES: Final = 8
MAX_PATH_POINTS: Final = (MAX_PAYLOAD - 2) // PATH_POINT_BYTES
"""The most points one ``getPath`` packet can carry (ARNL thins longer plans to fit)."""


@register
@dataclass(frozen=True, slots=True)
class GotoGoal(SingleField):
    """``gotoGoal`` args: the name of a ``Goal`` / ``GoalWithHeading`` of the map."""

    DATA_NAME = "gotoGoal"
    SIDE = Side.ARGS
    FIELD_KIND = "string"
    FIELD_LABEL = "goal name"

    goal: str


@register
@dataclass(frozen=True, slots=True)
class GotoPose(Payload):
    """``gotoPose`` args: ``byte4 x``, ``byte4 y`` (map mm) and an optional heading in degrees.

    ``th`` is None when no heading was sent: the robot then ends facing however it arrived.
    """

    DATA_NAME = "gotoPose"
    SIDE = Side.ARGS

    x: int
    y: int
    th: int | None = None
    short_th: bool = False
    """The heading came (or is to go) as the 2-byte int the API page documents, not ARNL's 4 bytes."""

    def encode(self) -> bytes:
        w = FieldWriter().byte4(self.x).byte4(self.y)
        if self.th is not None:
            if self.short_th:
                w.byte2(self.th)
            else:
                w.byte4(self.th)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        x, y = r.byte4("x"), r.byte4("y")
        if r.remaining >= 4:
            return cls(x, y, r.byte4("heading"))
        if r.remaining >= 2:
            return cls(x, y, r.byte2("heading"), short_th=True)
        return cls(x, y)


@register
@dataclass(frozen=True, slots=True)
class Home(EmptyPayload):
    """``home`` args (none): drive to the map's home (``RobotHome``, else where the robot started)."""

    DATA_NAME = "home"
    SIDE = Side.ARGS


@register
@dataclass(frozen=True, slots=True)
class TourGoals(EmptyPayload):
    """``tourGoals`` args (none): visit every goal of the map in turn, for ever."""

    DATA_NAME = "tourGoals"
    SIDE = Side.ARGS


@register
@dataclass(frozen=True, slots=True)
class Dock(Payload):
    """``dock`` args: nothing, or ARNL's optional ``ubyte`` (0 a normal dock, 1 a forced one).

    ``forced`` is None when the byte was left out, as clients normally do.
    """

    DATA_NAME = "dock"
    SIDE = Side.ARGS

    forced: int | None = None

    def encode(self) -> bytes:
        return b"" if self.forced is None else FieldWriter().ubyte(self.forced).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(None if r.at_end() else r.ubyte("forced flag"))


@register
@dataclass(frozen=True, slots=True)
class LocalizeToPose(Payload):
    """``localizeToPose`` args: ``byte4 x, y, th`` — the operator says where the robot really is.

    ARNL also reads two optional ``ubyte4`` spreads (mm, degrees) for its sample cloud; None when absent.
    """

    DATA_NAME = "localizeToPose"
    SIDE = Side.ARGS

    x: int
    y: int
    th: int
    xy_spread: int | None = None
    th_spread: int | None = None

    def encode(self) -> bytes:
        w = FieldWriter().byte4(self.x).byte4(self.y).byte4(self.th)
        if self.xy_spread is not None:
            w.ubyte4(self.xy_spread)
            if self.th_spread is not None:
                w.ubyte4(self.th_spread)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        x, y, th = r.byte4("x"), r.byte4("y"), r.byte4("heading")
        xy = None if r.at_end() else r.ubyte4("xy spread")
        th_spread = None if xy is None or r.at_end() else r.ubyte4("heading spread")
        return cls(x, y, th, xy, th_spread)


class LocalizationState(IntEnum):
    """``getLocState``'s first byte, as ARNL numbers it."""

    GOOD = 0
    IDLE = 1
    LOST = 2
    INITIALIZING = 3

    @property
    def label(self) -> str:
        return self.name.capitalize()


@register
@dataclass(frozen=True, slots=True)
class LocState(Payload):
    """``getLocState`` reply: ``ubyte`` state, ``ubyte2`` score (0 lost … :data:`LOC_SCORE_FULL`).

    A state outside 0–3 is kept as its number rather than refused.
    """

    DATA_NAME = "getLocState"
    SIDE = Side.REPLY

    state: int
    score: int

    @property
    def state_label(self) -> str:
        try:
            return LocalizationState(self.state).label
        except ValueError:
            return f"state {self.state}"

    @property
    def score_fraction(self) -> float:
        """The score as 0.0–1.0 (values above full scale, which no ARNL sends, read as 1.0)."""
        return min(self.score / LOC_SCORE_FULL, 1.0)

    def encode(self) -> bytes:
        return FieldWriter().ubyte(self.state).ubyte2(self.score).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(r.ubyte("localization state"), r.ubyte2("localization score"))


@register
@dataclass(frozen=True, slots=True)
class PlannedPath(Payload):
    """``getPath`` reply: ``byte2`` count, then ``byte4 x, byte4 y`` per point, map mm, robot → goal.

    No points (count 0) when nothing is being planned or followed.
    """

    DATA_NAME = "getPath"
    SIDE = Side.REPLY

    points: tuple[tuple[int, int], ...] = ()

    def encode(self) -> bytes:
        if len(self.points) > MAX_PATH_POINTS:
            raise PayloadError(f"{len(self.points)} path points do not fit one packet ({MAX_PATH_POINTS})")
        w = FieldWriter().byte2(len(self.points))
        for x, y in self.points:
            w.byte4(x).byte4(y)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        count = checked_count(r.byte2("point count"), PATH_POINT_BYTES, r, "point count")
        return cls(tuple((r.byte4("x"), r.byte4("y")) for _ in range(count)))


@register
@dataclass(frozen=True, slots=True)
class PathPlannerStatus(SingleField):
    """``pathPlannerStatus`` reply: the planner's own words for what it is doing or why it failed."""

    DATA_NAME = "pathPlannerStatus"
    SIDE = Side.REPLY
    FIELD_KIND = "string"
    FIELD_LABEL = "planner status"

    status: str


@register
@dataclass(frozen=True, slots=True)
class GoalName(SingleField):
    """``goalName`` reply: the goal being driven to or last driven to (``""`` for none or a point)."""

    DATA_NAME = "goalName"
    SIDE = Side.REPLY
    FIELD_KIND = "string"
    FIELD_LABEL = "goal name"

    goal: str

"""The server's drawings (``ArServerInfoDrawings``, protocol §4.4): what to draw on the map, and how.

``getDrawingList`` answers one packet per drawing — its data name, shape, colours, size, layer,
refresh period and visibility — and an empty packet at the end. Each drawing is then its own
data (``sonarCurrent``, ``sim_lms2xx_1Current``, or any name a server chose) whose reply is a
``byte4`` count and that many ``byte4`` x/y pairs in global mm: :class:`DrawingPoints`.

Everything here comes from the network, so it is bounded before anything is allocated: a point
count must fit in the bytes that follow (one packet holds at most 32 000 bytes, so at most
:data:`MAX_POINTS` points), and a list longer than :data:`MAX_DRAWINGS` is cut by the reader.
A shape this client does not know is kept as text (``Drawing.known_shape`` is None) so that a
caller can say so and leave it undrawn; nothing fails on it.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Final, Self

from ..fields import FieldReader, FieldWriter
from .base import Payload, Side, checked_count, read_xy, register, write_xy

MAX_POINTS: Final = 3998
"""Points one drawing packet can carry: (32 000-byte packet − 8 bytes framing − 4 count) / 8 a point."""
MAX_DRAWINGS: Final = 256
"""Drawings a client keeps from one list (ARIA servers list a handful: one per range device)."""
MAX_NAME: Final = 255
"""Characters of a name or shape kept (ARIA's own string fields are at most 255)."""

Point = tuple[int, int]


class Shape(StrEnum):
    """The shapes ARIA's ``ArDrawingData`` defines, as spelled on the wire."""

    POLY_DOTS = "polyDots"
    """A filled circle ``size`` mm across on each point (lasers)."""
    POLY_ARROWS = "polyArrows"
    """An arrow ``size`` mm long ending on each point, pointing at the robot (sonar)."""
    POLY_LINE = "polyLine"
    """One line through the points, ``size`` px wide (a path)."""
    POLY_POINTS = "polyPoints"
    """A one-pixel dot on each point (localization samples)."""
    POLY_SEGMENTS = "polySegments"
    """Segments from point 2i to point 2i+1, ``size`` px wide."""


class Visibility(StrEnum):
    """Whether a drawing is shown at first, and whether the operator may change that."""

    ALWAYS_ON = "AlwaysOn"
    DEFAULT_ON = "DefaultOn"
    DEFAULT_OFF = "DefaultOff"
    ALWAYS_OFF = "AlwaysOff"


@dataclass(frozen=True, slots=True)
class Drawing:
    """How a client should draw one data (usually a range device's ``<device>Current``)."""

    name: str
    """The data to request, e.g. ``sonarCurrent``."""
    shape: str
    """``polyDots``, ``polyArrows``, ``polyLine``, ``polyPoints``, ``polySegments`` (see :class:`Shape`)."""
    primary_color: int
    """0x00RRGGBB."""
    size: int
    """mm (dots, arrows) or px (lines, segments)."""
    layer: int
    """Drawing order: higher on top; the robot is layer 50, range devices start at 70."""
    refresh_ms: int
    """Suggested polling period; 0 = don't poll (the server sends it when it changes)."""
    secondary_color: int
    visibility: str = ""
    """e.g. ``DefaultOn`` (``getDrawingList`` only; "" means the default, ``DefaultOn``)."""

    @property
    def known_shape(self) -> Shape | None:
        """The shape, or None when this client does not know how to draw it."""
        try:
            return Shape(self.shape)
        except ValueError:
            return None

    @property
    def visibility_kind(self) -> Visibility:
        """An unknown or empty visibility reads as ARIA's default, ``DefaultOn``."""
        try:
            return Visibility(self.visibility)
        except ValueError:
            return Visibility.DEFAULT_ON

    @property
    def shown_by_default(self) -> bool:
        return self.visibility_kind in (Visibility.ALWAYS_ON, Visibility.DEFAULT_ON)

    @property
    def operator_may_toggle(self) -> bool:
        return self.visibility_kind in (Visibility.DEFAULT_ON, Visibility.DEFAULT_OFF)

    @property
    def rgb(self) -> tuple[float, float, float]:
        """The primary colour as cairo's 0…1 floats (the top byte is ignored, as ARIA does)."""
        c = self.primary_color
        return ((c >> 16) & 0xFF) / 255.0, ((c >> 8) & 0xFF) / 255.0, (c & 0xFF) / 255.0

    def _write(self, w: FieldWriter, with_visibility: bool) -> None:
        w.string(self.name).string(self.shape).byte4(self.primary_color).byte4(self.size)
        w.byte4(self.layer).ubyte4(self.refresh_ms).byte4(self.secondary_color)
        if with_visibility:
            w.string(self.visibility)

    @classmethod
    def _read(cls, r: FieldReader, with_visibility: bool) -> Drawing:
        return cls(
            r.string("drawing name")[:MAX_NAME],
            r.string("shape")[:MAX_NAME],
            r.byte4("primary color"),
            r.byte4("size"),
            r.byte4("layer"),
            r.ubyte4("default refresh time"),
            r.byte4("secondary color"),
            r.string("visibility")[:MAX_NAME] if with_visibility else "",
        )


@register
@dataclass(frozen=True, slots=True)
class DrawingListPacket(Payload):
    """One ``getDrawingList`` reply packet: a drawing, or None for the zero-length packet ending the list."""

    DATA_NAME = "getDrawingList"
    SIDE = Side.REPLY

    drawing: Drawing | None

    @property
    def end_of_reply(self) -> bool:
        return self.drawing is None

    def encode(self) -> bytes:
        if self.drawing is None:
            return b""
        w = FieldWriter()
        self.drawing._write(w, True)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        if not data:
            return cls(None)
        return cls(Drawing._read(FieldReader(data), True))


@register
@dataclass(frozen=True, slots=True)
class DrawingList(Payload):
    """``listDrawings`` reply (deprecated): ``byte4`` count, then drawings without visibility."""

    DATA_NAME = "listDrawings"
    SIDE = Side.REPLY

    drawings: tuple[Drawing, ...] = ()

    def encode(self) -> bytes:
        w = FieldWriter().byte4(len(self.drawings))
        for d in self.drawings:
            d._write(w, False)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        count = checked_count(r.byte4("drawing count"), 22, r, "drawing count")
        return cls(tuple(Drawing._read(r, False) for _ in range(min(count, MAX_DRAWINGS))))


@dataclass(frozen=True, slots=True)
class DrawingPoints:
    """One sample of a drawing's data: ``byte4`` count, then count × (``byte4`` x, ``byte4`` y), global mm.

    Not registered by name: a drawing's data name is whatever the server listed, so the caller
    that asked for it decodes it with this type. A count that the packet cannot hold is refused
    (``PayloadError``) before anything is allocated.
    """

    points: tuple[Point, ...] = ()

    def encode(self) -> bytes:
        w = FieldWriter().byte4(len(self.points))
        write_xy(w, self.points, "point")
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(read_xy(r, r.byte4("point count"), "point count"))

    def to_fields(self) -> dict[str, object]:
        return {"points": [list(p) for p in self.points]}

"""A hostile drawing server for tests: ARIA's layouts with bad names, shapes and sizes.

A scripted :class:`~tests.client.servers.TestServer` (real loopback sockets, the project's own
server codec) whose ``getDrawingList`` lists, beside an honest sonar:

* ``<b>bold</b> & _under_`` — markup and an underscore in a name (must be shown literally);
* ``blob`` — a shape nobody knows (``polyHexagons``): listed, never drawn, never asked for;
* ``huge`` — says it has 1 000 000 points but carries the bytes of only 3 998 (refused);
* ``max`` — the honest maximum, 3 998 points in one packet, every 20 ms (a flood); each sample moves
  its points (as a real sensor's do), so every one is news the window must show, never an unchanged
  repeat it may rightly skip.
"""

from __future__ import annotations

import itertools
import struct

from rtmu.protocol.payloads.drawings import MAX_POINTS, Drawing, DrawingListPacket, DrawingPoints

from .servers import SPECS, TestServer

MARKUP = "<b>bold</b> & _under_"
SONAR = Drawing("sonarCurrent", "polyArrows", 0x33CCFF, 200, 70, 200, 0, "DefaultOn")
BOLD = Drawing(MARKUP, "polyDots", 0xFF0000, 150, 72, 200, 0, "DefaultOn")
BLOB = Drawing("blob", "polyHexagons", 0x00FF00, 100, 73, 200, 0, "DefaultOn")
HUGE = Drawing("huge", "polyDots", 0x00FF00, 100, 74, 100, 0, "DefaultOn")
MAX = Drawing("max", "polyLine", 0xFF00FF, 1, 75, 20, 0, "DefaultOn")
DRAWINGS = (SONAR, BOLD, BLOB, HUGE, MAX)

SONAR_POINTS = ((1500, 2000), (1000, 2600))
BOLD_POINTS = ((600, 2000), (1400, 2000))
MAX_POINTS_SENT = tuple((1000 + (i % 400) * 5, 2000 + (i // 400) * 50) for i in range(MAX_POINTS))
MAX_SHIFTS_MM = (0, 20, 40, 60)
"""The flood's samples take turns among these shifts in x: consecutive samples always differ."""


def _row(name: str) -> tuple[str, str, str, str, str, str]:
    return (name, "", "none", "drawing", "SensorInfo", "RETURN_SINGLE")


def hostile_drawing_server() -> TestServer:
    specs = [*SPECS, ("getDrawingList", "drawings", "none", "list", "SensorInfo", "RETURN_UNTIL_EMPTY")]
    specs += [_row(d.name) for d in DRAWINGS]
    server = TestServer(specs)
    listing = [DrawingListPacket(d).encode() for d in DRAWINGS] + [DrawingListPacket(None).encode()]
    honest_max = DrawingPoints(MAX_POINTS_SENT).encode()
    moving_max = itertools.cycle(
        [DrawingPoints(tuple((x + dx, y) for x, y in MAX_POINTS_SENT)).encode() for dx in MAX_SHIFTS_MM]
    )
    lying = struct.pack("<i", 1_000_000) + honest_max[4:]
    server.handlers.update(
        {
            "getDrawingList": lambda s, a: listing,
            SONAR.name: lambda s, a: [DrawingPoints(SONAR_POINTS).encode()],
            BOLD.name: lambda s, a: [DrawingPoints(BOLD_POINTS).encode()],
            BLOB.name: lambda s, a: [DrawingPoints(((0, 0),)).encode()],
            HUGE.name: lambda s, a: [lying],
            MAX.name: lambda s, a: [next(moving_max)],
        }
    )
    return server


def drawings_server(
    drawings: tuple[Drawing, ...], points: tuple[tuple[int, int], ...] = ((1, 2),)
) -> TestServer:
    """A server listing ``drawings`` in that order, each answering with ``points``."""
    specs = [*SPECS, ("getDrawingList", "drawings", "none", "list", "SensorInfo", "RETURN_UNTIL_EMPTY")]
    specs += [_row(d.name) for d in drawings]
    server = TestServer(specs)
    listing = [DrawingListPacket(d).encode() for d in drawings] + [DrawingListPacket(None).encode()]
    sample = DrawingPoints(points).encode()
    server.handlers["getDrawingList"] = lambda s, a: listing
    for d in drawings:
        server.handlers[d.name] = lambda s, a: [sample]
    return server


FOREVER = Drawing("forever", "polyDots", 0x0000FF, 100, 60, 0xFFFFFFFF, 0, "DefaultOn")
"""Asks to be refreshed every 2³²−1 ms: more than a request's signed 32-bit period can say."""
AFTER = Drawing("after", "polyDots", 0x00FF00, 100, 61, 200, 0, "DefaultOn")
"""Comes after it in layer order: it must still be asked for."""


def many(count: int) -> tuple[Drawing, ...]:
    return tuple(
        Drawing(f"d{n:03d}", "polyDots", 0x00FF00, 100, 60 + n % 20, 1000, 0, "DefaultOn")
        for n in range(count)
    )

"""Asking a server for its drawings: the list (``getDrawingList``) and one sample of a drawing's data.

Shared by the window's :mod:`~rtmu.client.drawings_feed` and ``rtmu drawings``. The list is
bounded: the first :data:`~rtmu.protocol.payloads.drawings.MAX_DRAWINGS` drawings are kept and
the rest counted (:attr:`DrawingList.dropped`), and a list that has not ended after
:data:`MAX_LISTED` packets is given up on there (:attr:`DrawingList.cut`). A drawing whose data
the server does not list for this user is left out, since asking for it could never be answered.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..protocol.errors import ProtocolError
from ..protocol.payloads.drawings import MAX_DRAWINGS, Drawing, DrawingListPacket, DrawingPoints
from .connection import AriaClient
from .errors import MalformedReply, NotSupported

LIST = "getDrawingList"
MAX_LISTED = 4096
"""Packets of a drawing list read at most: one that has not ended by then is given up on."""
MAX_LIST_BYTES = 4 * 1024 * 1024
"""List bytes that may wait to be read (a drawing is some 60 bytes; a flood of 32 kB ones fails)."""


@dataclass(frozen=True, slots=True)
class DrawingList:
    drawings: tuple[Drawing, ...]
    """The drawings kept, in the server's order, names unique."""
    dropped: int = 0
    """Drawings listed beyond :data:`MAX_DRAWINGS`: neither shown nor asked for."""
    cut: bool = False
    """The list had not ended after :data:`MAX_LISTED` packets (more may have been dropped)."""

    def dropped_text(self) -> str:
        """What was left out, in words for the operator ("" when nothing was)."""
        if not self.dropped:
            return ""
        more = "at least " if self.cut else ""
        return (
            f"the server lists {more}{MAX_DRAWINGS + self.dropped} drawings; the first {MAX_DRAWINGS} are "
            f"kept and {more}{self.dropped} left out"
        )


async def drawing_list(client: AriaClient, timeout: float) -> DrawingList:
    """The server's drawings in its order (NotSupported without ``getDrawingList``); names are unique."""
    if not client.supports(LIST):
        raise NotSupported(LIST, "this server lists no drawings (getDrawingList)")
    out: dict[str, Drawing] = {}
    dropped = seen = 0
    cut = False
    packets = client.stream(LIST, timeout=timeout, max_packets=MAX_LISTED + 1, max_bytes=MAX_LIST_BYTES)
    try:
        async for payload in packets:
            seen += 1
            try:
                packet = DrawingListPacket.decode(payload)
            except ProtocolError as exc:
                raise MalformedReply(f"the server sent a malformed {LIST!r} packet: {exc}") from None
            d = packet.drawing
            if d is not None and d.name not in out and client.supports(d.name):
                if len(out) < MAX_DRAWINGS:
                    out[d.name] = d
                else:
                    dropped += 1
            if seen >= MAX_LISTED:
                cut = True
                break
    finally:  # left early (cut, malformed): the request is abandoned, its late packets dropped
        closing = getattr(packets, "aclose", None)
        if closing is not None:
            await closing()
    return DrawingList(tuple(out.values()), dropped, cut)


async def drawing_sample(client: AriaClient, name: str, timeout: float) -> DrawingPoints:
    """One current sample of drawing ``name`` (MalformedReply when its count does not fit its bytes)."""
    reply = await client.request_once(name, timeout=timeout, max_packets=1)
    return decode_points(name, reply.payload)


def decode_points(name: str, payload: bytes) -> DrawingPoints:
    try:
        return DrawingPoints.decode(payload)
    except ProtocolError as exc:
        raise MalformedReply(f"the server sent a malformed {name!r} drawing: {exc}") from None

"""Asking a server for its drawings: the list (``getDrawingList``) and one sample of a drawing's data.

Shared by the window's :mod:`~rtmu.client.drawings_feed` and ``rtmu drawings``. The list is
bounded (:data:`~rtmu.protocol.payloads.drawings.MAX_DRAWINGS` packets, then the request fails
as too large); a drawing whose data the server does not list for this user is left out, since
asking for it could never be answered.
"""

from __future__ import annotations

from ..protocol.errors import ProtocolError
from ..protocol.payloads.drawings import MAX_DRAWINGS, Drawing, DrawingListPacket, DrawingPoints
from .connection import AriaClient
from .errors import MalformedReply, NotSupported

LIST = "getDrawingList"


async def drawing_list(client: AriaClient, timeout: float) -> tuple[Drawing, ...]:
    """The server's drawings in its order (NotSupported without ``getDrawingList``); names are unique."""
    if not client.supports(LIST):
        raise NotSupported(LIST, "this server lists no drawings (getDrawingList)")
    reply = await client.request_once(LIST, timeout=timeout, max_packets=MAX_DRAWINGS + 1)
    out: dict[str, Drawing] = {}
    for payload in reply.payloads:
        try:
            packet = DrawingListPacket.decode(payload)
        except ProtocolError as exc:
            raise MalformedReply(f"the server sent a malformed {LIST!r} packet: {exc}") from None
        d = packet.drawing
        if d is not None and d.name not in out and client.supports(d.name):
            out[d.name] = d
    return tuple(out.values())


async def drawing_sample(client: AriaClient, name: str, timeout: float) -> DrawingPoints:
    """One current sample of drawing ``name`` (MalformedReply when its count does not fit its bytes)."""
    reply = await client.request_once(name, timeout=timeout, max_packets=1)
    return decode_points(name, reply.payload)


def decode_points(name: str, payload: bytes) -> DrawingPoints:
    try:
        return DrawingPoints.decode(payload)
    except ProtocolError as exc:
        raise MalformedReply(f"the server sent a malformed {name!r} drawing: {exc}") from None

"""Sans-I/O ArNetworking codec: bytes in, events out; requests in, bytes out.

Never imports asyncio, sockets or GTK. One codec serves both the client and the
bundled simulator.

The names below are imported from their modules when first used, so that importing one module
of the codec (``rtmu.protocol.commands`` for a constant) does not load the rest of it. The
checksum function is ``rtmu.protocol.checksum.checksum`` (the package's ``checksum`` is that module).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from . import lazy

if TYPE_CHECKING:
    from .commands import ClientCommand, ClientType, RejectReason, ServerCommand
    from .datalist import DataEntry, DataList
    from .decoder import DropStats, PacketDecoder
    from .errors import FieldUnderrun, PacketTooLong, PayloadError, ProtocolError
    from .fields import FieldReader, FieldWriter
    from .packet import MAX_LENGTH, MAX_PAYLOAD, Packet, encode_packet

__getattr__ = lazy.exports(
    __name__,
    {
        "ClientCommand": "commands",
        "ClientType": "commands",
        "RejectReason": "commands",
        "ServerCommand": "commands",
        "DataEntry": "datalist",
        "DataList": "datalist",
        "DropStats": "decoder",
        "PacketDecoder": "decoder",
        "FieldUnderrun": "errors",
        "PacketTooLong": "errors",
        "PayloadError": "errors",
        "ProtocolError": "errors",
        "FieldReader": "fields",
        "FieldWriter": "fields",
        "MAX_LENGTH": "packet",
        "MAX_PAYLOAD": "packet",
        "Packet": "packet",
        "encode_packet": "packet",
    },
)


__all__ = [
    "MAX_LENGTH",
    "MAX_PAYLOAD",
    "ClientCommand",
    "ClientType",
    "DataEntry",
    "DataList",
    "DropStats",
    "FieldReader",
    "FieldUnderrun",
    "FieldWriter",
    "Packet",
    "PacketDecoder",
    "PacketTooLong",
    "PayloadError",
    "ProtocolError",
    "RejectReason",
    "ServerCommand",
    "encode_packet",
]

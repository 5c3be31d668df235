"""Sans-I/O ArNetworking codec: bytes in, events out; requests in, bytes out.

Never imports asyncio, sockets or GTK. One codec serves both the client and the
bundled simulator.
"""

from .checksum import checksum
from .commands import ClientCommand, ClientType, RejectReason, ServerCommand
from .datalist import DataEntry, DataList
from .decoder import DropStats, PacketDecoder
from .errors import FieldUnderrun, PacketTooLong, PayloadError, ProtocolError
from .fields import FieldReader, FieldWriter
from .packet import MAX_LENGTH, MAX_PAYLOAD, Packet, encode_packet

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
    "checksum",
    "encode_packet",
]

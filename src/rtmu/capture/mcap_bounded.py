"""Reading an untrusted MCAP file with its decompression bounded before it happens.

The ``mcap`` package's reader decompresses a chunk to whatever size the chunk claims and turns
all its records into a list at once: an 8.5 kB file of zstd "bombs" took ``rtmu decode`` to
565 MB and ``rtmu replay`` past 1 GB, a 23 kB one of 8-byte messages past 7 GB. The 64 MB bound
on a record limited only the compressed bytes. Here each chunk is weighed first, from its own
header, and refused with the reason (:class:`McapBoundError`) before a byte is inflated when

* it claims more than :data:`MAX_CHUNK_BYTES` uncompressed (RTMU closes a chunk at 512 kB or each
  second; one camera picture or map is far below this), or
* it claims to expand more than :data:`MAX_RATIO` times (RTMU's chunks expand 3–6 times: a ratio of
  hundreds is a bomb, not a recording), or
* the file's chunks together would exceed the reader's ``budget``;

then it is inflated into at most its claimed size (one byte more is a lie, and refused too), and its
records are read one at a time, never listed. Records outside chunks are read as the ``mcap``
package reads them, with its record size limit.
"""

from __future__ import annotations

import io
import struct
import zlib
from collections.abc import Iterator
from typing import IO

from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.records import Channel, Chunk, Message, Schema
from mcap.stream_reader import StreamReader

MAX_RECORD = 64 * 1024 * 1024
"""A record (a compressed chunk) larger than this is not one RTMU wrote."""
MAX_CHUNK_BYTES = 64 * 1024 * 1024
"""Uncompressed bytes one chunk may claim."""
MAX_RATIO = 200
"""How many times its compressed size a chunk may claim to expand (plus :data:`RATIO_SLACK`)."""
RATIO_SLACK = 64 * 1024
"""Tiny chunks (a few records) may expand beyond the ratio up to this."""
MAX_ZSTD_WINDOW = 16 * 1024 * 1024
"""The most memory a zstd frame may ask for its window (every standard level stays under 8 MB)."""
DEFAULT_BUDGET = 16 * 1024 * 1024 * 1024
"""Uncompressed bytes a whole file may claim (16 GB: hours of a real camera at the ratio above)."""
_RECORD_HEAD = struct.Struct("<BQ")
_MESSAGE_HEAD = struct.Struct("<HIQQ")


class McapBoundError(ValueError):
    """The file asks for more than a recording may: the sentence says what and how much."""


def _mb(n: int) -> str:
    return f"{n / 1e6:.1f} MB"


class BoundedMcap:
    """``for schema, channel, message in BoundedMcap(file).messages(): …`` — in file order."""

    def __init__(
        self, stream: IO[bytes], *, budget: int = DEFAULT_BUDGET, validate_crcs: bool = True
    ) -> None:
        self._stream = stream
        self.budget = budget
        self.validate_crcs = validate_crcs
        self.inflated = 0
        """Uncompressed bytes of the chunks read so far."""
        self.chunks = 0
        self._schemas: dict[int, Schema] = {}
        self._channels: dict[int, Channel] = {}

    def messages(self) -> Iterator[tuple[Schema | None, Channel, Message]]:
        reader = StreamReader(
            self._stream, emit_chunks=True, validate_crcs=self.validate_crcs, record_size_limit=MAX_RECORD
        )
        for record in reader.records:
            if isinstance(record, Chunk):
                yield from self._chunk(record)
            else:
                found = self._record(record)
                if found is not None:
                    yield found

    def _record(self, record: object) -> tuple[Schema | None, Channel, Message] | None:
        if isinstance(record, Schema):
            self._schemas[record.id] = record
        elif isinstance(record, Channel):
            self._channels[record.id] = record
        elif isinstance(record, Message):
            channel = self._channels.get(record.channel_id)
            if channel is None:
                raise McapBoundError(
                    f"a message names channel {record.channel_id}, which the file never defined"
                )
            return self._schemas.get(channel.schema_id), channel, record
        return None

    # -- chunks -----------------------------------------------------------------------------------
    def _chunk(self, chunk: Chunk) -> Iterator[tuple[Schema | None, Channel, Message]]:
        self.chunks += 1
        claimed, packed = chunk.uncompressed_size, len(chunk.data)
        where = f"chunk {self.chunks}"
        if claimed > MAX_CHUNK_BYTES:
            raise McapBoundError(
                f"{where} claims {_mb(claimed)} uncompressed, over the {_mb(MAX_CHUNK_BYTES)} a recording's "
                "chunk may hold: refused before decompressing (a decompression bomb?)"
            )
        if claimed > MAX_RATIO * packed + RATIO_SLACK:
            raise McapBoundError(
                f"{where} claims to expand {packed} bytes into {_mb(claimed)} (over {MAX_RATIO}×): refused "
                "before decompressing (a decompression bomb?)"
            )
        if self.inflated + claimed > self.budget:
            raise McapBoundError(
                f"the file's chunks claim over {_mb(self.budget)} uncompressed, more than this reader "
                f"holds: refused at {where}, before decompressing it"
            )
        self.inflated += claimed
        data = _inflate(chunk, where)
        if self.validate_crcs and chunk.uncompressed_crc != 0 and zlib.crc32(data) != chunk.uncompressed_crc:
            raise McapBoundError(f"{where}'s contents fail their CRC: the file is damaged")
        view = memoryview(data)
        at = 0
        while at < len(view):
            if at + _RECORD_HEAD.size > len(view):
                raise McapBoundError(f"{where} ends inside a record's header")
            opcode, length = _RECORD_HEAD.unpack_from(view, at)
            at += _RECORD_HEAD.size
            if length > len(view) - at:
                raise McapBoundError(f"{where} holds a record longer than the chunk")
            body = view[at : at + length]
            at += length
            if opcode == Opcode.MESSAGE:
                found = self._record(_message(body, where))
            elif opcode == Opcode.CHANNEL:
                found = self._record(Channel.read(ReadDataStream(io.BytesIO(body))))
            elif opcode == Opcode.SCHEMA:
                found = self._record(Schema.read(ReadDataStream(io.BytesIO(body))))
            else:
                continue  # a record kind a chunk may hold that carries no message
            if found is not None:
                yield found


def _message(body: memoryview, where: str) -> Message:
    if len(body) < _MESSAGE_HEAD.size:
        raise McapBoundError(f"{where} holds a message record too short for its header")
    channel_id, sequence, log_time, publish_time = _MESSAGE_HEAD.unpack_from(body)
    return Message(
        channel_id=channel_id,
        sequence=sequence,
        log_time=log_time,
        publish_time=publish_time,
        data=bytes(body[_MESSAGE_HEAD.size :]),
    )


def _inflate(chunk: Chunk, where: str) -> bytes:
    """The chunk's records, never more than it claimed (one byte more and it lied: refused)."""
    claimed = chunk.uncompressed_size
    if chunk.compression == "":
        data = bytes(chunk.data)
    elif chunk.compression == "zstd":
        import zstandard

        try:
            inflater = zstandard.ZstdDecompressor(max_window_size=MAX_ZSTD_WINDOW)
            reader = inflater.stream_reader(io.BytesIO(chunk.data), read_across_frames=True)
            parts: list[bytes] = []
            got = 0
            while got <= claimed:
                piece = reader.read(claimed + 1 - got)
                if not piece:
                    break
                parts.append(piece)
                got += len(piece)
            data = b"".join(parts)
        except zstandard.ZstdError as exc:
            raise McapBoundError(f"{where} does not decompress: {exc}") from None
    elif chunk.compression == "lz4":
        try:
            import lz4.frame
        except ImportError:
            raise McapBoundError(f"{where} is lz4-compressed and lz4 is not installed") from None
        try:
            data = lz4.frame.LZ4FrameDecompressor().decompress(chunk.data, max_length=claimed + 1)
        except RuntimeError as exc:
            raise McapBoundError(f"{where} does not decompress: {exc}") from None
    else:
        raise McapBoundError(
            f"{where} is compressed with {chunk.compression[:20]!r}, which RTMU does not read"
        )
    if len(data) != claimed:
        held = "more" if len(data) > claimed else "fewer"
        raise McapBoundError(f"{where} claims {claimed} bytes uncompressed but holds {held}")
    return data

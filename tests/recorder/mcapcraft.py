"""Hostile MCAP files, written byte by byte from the format's specification (records, chunks, lies).

RTMU's writer never makes these; a file from anyone else may be anything. Each record is
``opcode u8, length u64, body``; a chunk's body claims its uncompressed size, which is what a
decompression bomb lies about (or tells the truth about, hugely).
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import zstandard

from rtmu.capture.recorded import CONNECTION_TOPIC, RAW_ENCODING, RAW_SCHEMA, RAW_TOPICS

MAGIC = b"\x89MCAP0\r\n"


def _s(text: str) -> bytes:
    data = text.encode()
    return struct.pack("<I", len(data)) + data


def record(opcode: int, body: bytes) -> bytes:
    return struct.pack("<BQ", opcode, len(body)) + body


def schema(sid: int, name: str, encoding: str = "", data: bytes = b"") -> bytes:
    return record(
        0x03, struct.pack("<H", sid) + _s(name) + _s(encoding) + struct.pack("<I", len(data)) + data
    )


def channel(cid: int, sid: int, topic: str, encoding: str) -> bytes:
    return record(0x04, struct.pack("<HH", cid, sid) + _s(topic) + _s(encoding) + struct.pack("<I", 0))


def message(cid: int, seq: int, at_ns: int, data: bytes) -> bytes:
    return record(0x05, struct.pack("<HIQQ", cid, seq, at_ns, at_ns) + data)


def chunk(records: bytes, *, compressed: bytes | None = None, claimed: int | None = None) -> bytes:
    """A zstd chunk of ``records`` (or ``compressed`` as given) claiming ``claimed`` bytes (default: true)."""
    data = compressed if compressed is not None else zstandard.ZstdCompressor().compress(records)
    size = len(records) if claimed is None else claimed
    crc = zlib.crc32(records) if compressed is None and claimed is None else 0
    body = struct.pack("<QQQI", 0, 0, size, crc) + _s("zstd") + struct.pack("<Q", len(data)) + data
    return record(0x06, body)


def raw_channels() -> bytes:
    """The schema and channels of RTMU's raw ArNetworking bytes (channel 1: c2s, 2: s2c, 3: connection)."""
    return (
        schema(1, RAW_SCHEMA)
        + channel(1, 1, RAW_TOPICS["c2s"], RAW_ENCODING)
        + channel(2, 1, RAW_TOPICS["s2c"], RAW_ENCODING)
        + channel(3, 0, CONNECTION_TOPIC, "json")
    )


def connection() -> bytes:
    return message(3, 0, 1, b'{"conn": 1, "host": "127.0.0.1", "port": 7272}')


def mcap_file(path: Path, *chunks_and_records: bytes) -> Path:
    header = record(0x01, _s("") + _s("mcapcraft"))
    end = record(0x0F, struct.pack("<I", 0)) + record(0x02, struct.pack("<QQI", 0, 0, 0))
    path.write_bytes(MAGIC + header + b"".join(chunks_and_records) + end + MAGIC)
    return path


def zeros_zstd(size: int, prefix: bytes = b"") -> bytes:
    """``prefix`` and ``size`` zero bytes compressed by zstd, a megabyte at a time (never all held)."""
    compressor = zstandard.ZstdCompressor().compressobj()
    piece = bytes(1 << 20)
    out = [compressor.compress(prefix)]
    out += [compressor.compress(piece) for _ in range(size >> 20)]
    out.append(compressor.compress(bytes(size & ((1 << 20) - 1))))
    out.append(compressor.flush())
    return b"".join(out)


def bomb(size: int) -> bytes:
    """A true chunk: one raw message of ``size`` zero bytes. Tiny compressed; ``size`` when inflated."""
    head = struct.pack("<BQ", 0x05, 22 + size) + struct.pack("<HIQQ", 2, 1, 2, 2)
    return chunk(b"", compressed=zeros_zstd(size, head), claimed=len(head) + size)

"""ArServerFileUtils' and ArServerHandlerMapping's payloads: ARIA's bytes, hostile counts, scan names."""

from __future__ import annotations

import struct

import pytest

from rtmu.protocol.errors import ProtocolError
from rtmu.protocol.payloads import Side, payload_type_for
from rtmu.protocol.payloads.files import (
    DeleteFileReply,
    DirEntry,
    DirListing,
    DirListingPacket,
    FileChunk,
    GetFileRequest,
    PutFileCommand,
    PutFileReply,
    PutFileRequest,
    PutFileWithTimestampInterleavedReply,
    PutFileWithTimestampRequest,
    TimestampedFileChunk,
)
from rtmu.protocol.payloads.mapping import (
    MappingEndReply,
    MappingStartReply,
    MappingStatusBroadcast,
    scan_file_name,
)


def u2(v: int) -> bytes:
    return struct.pack("<H", v)


def u4(v: int) -> bytes:
    return struct.pack("<I", v)


def test_dir_listing_reads_folders_then_files_as_aria_writes_them() -> None:
    raw = (
        u2(0) + b"maps\0"
        + u2(1) + b"old\0" + u4(10) + u4(20) + u4(4096)
        + u2(2) + b"a.map\0" + u4(1) + u4(2) + u4(3) + b"B.map\0" + u4(4) + u4(5) + u4(6)
    )  # fmt: skip
    listing = DirListing.decode(raw)
    assert listing.code == 0 and listing.folder == "maps"
    assert [(e.name, e.is_folder, e.size) for e in listing.entries] == [
        ("old", True, 4096),
        ("a.map", False, 3),
        ("B.map", False, 6),
    ]
    assert listing.encode() == raw


def test_an_error_listing_is_the_code_and_the_folder_only() -> None:
    assert DirListing.decode(u2(1) + b"../etc\0") == DirListing(1, "../etc")
    assert DirListingPacket.decode(u2(2) + b"nope\0") == DirListingPacket(2, "nope")


def test_multi_packet_listing_entries_carry_their_kind_and_an_empty_packet_ends() -> None:
    raw = u2(0) + b"\0" + u2(2) + b"\x01d\0" + u4(1) * 3 + b"\x02f.2d\0" + u4(7) + u4(8) + u4(9)
    packet = DirListingPacket.decode(raw)
    assert packet.entries == (DirEntry(1, "d", 1, 1, 1), DirEntry(2, "f.2d", 7, 8, 9))
    assert DirListingPacket.decode(b"") == DirListingPacket(end=True)


@pytest.mark.parametrize(
    "raw",
    [
        u2(0) + b"\0" + u2(65535),  # 65 535 entries claimed in a few bytes
        u2(0) + b"\0" + u2(3) + b"\x02a\0" + u4(1),
    ],
)
def test_a_count_that_cannot_fit_is_refused_before_anything_is_read(raw: bytes) -> None:
    with pytest.raises(ProtocolError):
        DirListingPacket.decode(raw)


def test_get_file_packets_as_aria_sends_them() -> None:
    assert GetFileRequest("maps/a.map").encode() == b"maps/a.map\0" + u2(0)
    chunk = FileChunk.decode(u2(0) + b"a.map\0" + u4(3) + b"abc")
    assert chunk.data == b"abc" and not chunk.end_of_file
    assert FileChunk.decode(u2(0) + b"a.map\0" + u4(0)).end_of_file
    assert FileChunk.decode(b"").end
    assert FileChunk.decode(u2(2) + b"a.map\0") == FileChunk(2, "a.map")
    # ARIA writes the count first, then the time (its help text says the other way round)
    stamped = TimestampedFileChunk.decode(u2(0) + b"a\0" + u4(2) + struct.pack("<i", 1700000000) + b"hi")
    assert (stamped.data, stamped.mtime) == (b"hi", 1700000000)


def test_a_file_packet_that_lies_about_its_size_is_refused() -> None:
    with pytest.raises(ProtocolError, match="claims 4294967295 bytes but carries 3"):
        FileChunk.decode(u2(0) + b"a\0" + u4(0xFFFFFFFF) + b"abc")
    with pytest.raises(ProtocolError):
        PutFileRequest.decode(u2(1) + b"a\0" + u4(1 << 30) + b"x")


def test_put_file_packets() -> None:
    assert PutFileRequest(PutFileCommand.DATA, "a", b"xy").encode() == u2(1) + b"a\0" + u4(2) + b"xy"
    assert PutFileRequest(PutFileCommand.DONE, "a").encode() == u2(2) + b"a\0"
    start = PutFileWithTimestampRequest(PutFileCommand.START, "a", mtime=5)
    assert start.encode() == u2(0) + b"a\0" + struct.pack("<i", 5)
    assert PutFileReply.decode(u2(10) + b"a\0") == PutFileReply(10, "a")
    found = payload_type_for("putFileWithTimestampInterleaved", Side.REPLY)
    assert found is PutFileWithTimestampInterleavedReply
    assert DeleteFileReply.decode(u2(0) + b"x\0").code == 0


def test_mapping_end_is_two_bytes_except_for_nothing_to_end() -> None:
    assert MappingEndReply.decode(u2(0)).code == 0
    assert MappingEndReply.decode(u2(2)).code == 2
    assert MappingEndReply.decode(b"\x01").code == 1
    assert MappingEndReply(0).encode() == u2(0) and MappingEndReply(1).encode() == b"\x01"
    assert MappingStartReply.decode(b"\x01").code == 1
    assert MappingStatusBroadcast.decode(b"lab.2d\0").name == "lab.2d"


@pytest.mark.parametrize(
    ("name", "file"),
    [
        ("Lab", "lab.2d"),
        ("lab.2d", "lab.2d"),
        ("Office.2D", "office.2d"),
        ("x.2dd", "x.2dd"),
        ("ÄB", "Äb.2d"),
    ],
)
def test_scan_file_name_follows_aria(name: str, file: str) -> None:
    assert scan_file_name(name) == file

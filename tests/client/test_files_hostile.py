"""Hostile file and scan servers: every lie gets a clear error, and nothing is written where it must not be.

A small scripted ArNetworking server of our own (``servers.TestServer``) answers the file and mapping
requests with what a hostile or broken robot could send: names that climb out of the folder, hold a
slash or a control character, listings of 10⁵ entries, a ``getFile`` whose packets lie about their size,
that sends more than it listed or never ends, a ``putFile`` refused half-way, a scan whose name is a path.
Over real loopback sockets, through the client functions and ``rtmu files`` / ``rtmu scan``.
"""

from __future__ import annotations

import asyncio
import struct
from collections.abc import Awaitable, Callable
from pathlib import Path
from typing import Any

import pytest

from rtmu.base.exit_codes import EXIT_CONNECTION, EXIT_REFUSED, EXIT_UNSUPPORTED
from rtmu.cli import main
from rtmu.client.connection import AriaClient
from rtmu.client.download import SizeLie, download_file
from rtmu.client.errors import ClientTimeout, MalformedReply, NotSupported
from rtmu.client.remote_files import ListingTooLarge, Refused, UnsafeName, default_folder, list_folder
from rtmu.client.upload import upload_file
from rtmu.protocol.payloads.files import DirEntry, DirListingPacket, FileChunk, PutFileReply, PutFileRequest
from rtmu.values.target import Target

from .servers import SPECS, ServerSide, ServerThread, TestServer, run

FILE_SPECS = [
    (
        "getDirListingMultiplePackets",
        "list",
        "string",
        "entries",
        "FileAccess",
        "RETURN_UNTIL_EMPTY|SLOW_PACKET",
    ),
    ("getFile", "get", "string", "chunks", "FileAccess", "RETURN_UNTIL_EMPTY|SLOW_PACKET"),
    ("putFile", "put", "command", "code", "FileAccess", "DO_NOT_FORWARD|RETURN_COMPLEX|SLOW_PACKET"),
    (
        "putFileInterleaved",
        "put",
        "command",
        "code",
        "FileAccess",
        "DO_NOT_FORWARD|RETURN_SINGLE|SLOW_PACKET",
    ),
    ("getDefaultUploadDownloadDir", "dir", "none", "string", "FileAccess", "RETURN_SINGLE|SLOW_PACKET"),
    ("mappingStatus", "status", "none", "string", "RobotInfo", "RETURN_SINGLE"),
    ("mappingStart", "start", "string", "byte", "Mapping", "RETURN_SINGLE"),
    ("mappingEnd", "end", "none", "ubyte2", "Mapping", "RETURN_SINGLE"),
]


def file_entry(name: str, size: int = 10) -> DirEntry:
    return DirEntry(2, name, 1, 2, size)


def listing(*entries: DirEntry, folder: str = "") -> list[bytes]:
    return [DirListingPacket(0, folder, entries).encode(), b""]


def file_server(entries: tuple[DirEntry, ...] = (file_entry("a.map"),)) -> TestServer:
    server = TestServer(SPECS + FILE_SPECS)
    server.handlers["getDirListingMultiplePackets"] = lambda s, a: listing(*entries)
    server.handlers["getDefaultUploadDownloadDir"] = lambda s, a: [b"maps\0"]
    return server


def with_client(server: TestServer, body: Callable[[AriaClient], Awaitable[Any]]) -> Any:
    with ServerThread(server) as running:

        async def go() -> Any:
            client = AriaClient()
            await client.connect(Target("127.0.0.1", running.port), timeout=5)
            try:
                return await body(client)
            finally:
                await client.disconnect()

        return run(go(), 60)


def left_in(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


@pytest.mark.parametrize(
    ("name", "words"),
    [
        ("../../etc/passwd", "holds a slash"),
        ("..", "folder above"),
        ("a/b", "holds a slash"),
        ("evil\x1b[2Jname", "control character"),
        ("new\nline", "control character"),
        (".bashrc", "starts with a dot"),
        ("", "empty"),
        ("x" * 300, "longer than 255"),
    ],
    ids=["climbs-out", "dotdot", "slash", "escape", "newline", "dotfile", "empty", "long"],
)
def test_a_listing_with_a_name_that_is_no_plain_file_name_is_refused(
    name: str, words: str, tmp_path: Path, capsys
) -> None:  # type: ignore[no-untyped-def]
    server = file_server((file_entry("fine.map"), file_entry(name)))

    async def body(c: AriaClient) -> None:
        with pytest.raises(UnsafeName, match=words):
            await list_folder(c)
        with pytest.raises(UnsafeName):
            await download_file(c, "fine.map", tmp_path / "fine.map")

    with_client(server, body)
    assert left_in(tmp_path) == []
    with ServerThread(file_server((file_entry(name),))) as running:
        code = main(["files", f"127.0.0.1:{running.port}", "ls", "--timeout", "3"])
    err = capsys.readouterr().err
    assert code == EXIT_CONNECTION and "not a plain file name" in err
    assert "\x1b" not in err and "\n" not in err.rstrip("\n")  # shown escaped, on one line


def test_a_listing_of_a_hundred_thousand_entries_is_stopped(tmp_path: Path) -> None:
    server = TestServer(SPECS + FILE_SPECS)
    per_packet = 1250
    packet = DirListingPacket(0, "", tuple(file_entry(f"f{i:06d}") for i in range(per_packet))).encode()
    server.handlers["getDirListingMultiplePackets"] = lambda s, a: [packet] * (100_000 // per_packet) + [b""]

    async def body(c: AriaClient) -> None:
        with pytest.raises(ListingTooLarge, match="more than 20000 entries"):
            await list_folder(c)
        # the connection is still good for the next request
        assert (await c.request_once("getDefaultUploadDownloadDir")).payload == b"maps\0"

    server.handlers["getDefaultUploadDownloadDir"] = lambda s, a: [b"maps\0"]
    with_client(server, body)


def send_later(side: ServerSide, name: str, payloads: list[bytes]) -> None:
    for p in payloads:
        side.conn.send_data(name, p)
    side.writer.write(side.conn.data_to_send())


def test_a_file_packet_that_lies_about_its_size_saves_nothing(tmp_path: Path) -> None:
    server = file_server((file_entry("a.map", 100),))
    lie = struct.pack("<HB", 0, 0)[:2] + b"a.map\0" + struct.pack("<I", 30_000) + b"short"
    server.handlers["getFile"] = lambda s, a: [lie, b""]

    async def body(c: AriaClient) -> None:
        with pytest.raises(MalformedReply, match="claims 30000 bytes but carries 5"):
            await download_file(c, "a.map", tmp_path / "a.map")

    with_client(server, body)
    assert left_in(tmp_path) == []


def endless(side: ServerSide, args: bytes) -> None:
    """Chunks of the file for ever, as fast as the client reads (a robot that never ends the file)."""

    async def flood() -> None:
        chunk = FileChunk(0, "a.map", b"x" * 30_000).encode()
        while not side.writer.is_closing():
            side.conn.send_data("getFile", chunk)
            side.writer.write(side.conn.data_to_send())
            await side.writer.drain()
            await asyncio.sleep(0)

    side.subs["flood"] = asyncio.get_running_loop().create_task(flood())


def test_a_file_longer_than_listed_is_cut_off_and_nothing_saved(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    server = file_server((file_entry("a.map", 100),))
    server.handlers["getFile"] = endless

    async def body(c: AriaClient) -> None:
        with pytest.raises(SizeLie, match=r"more bytes of 'a\.map' than the 100 it listed"):
            await download_file(c, "a.map", tmp_path / "a.map")

    with_client(server, body)
    assert left_in(tmp_path) == []
    with ServerThread(file_server((file_entry("a.map", 100),))) as running:
        running.handlers["getFile"] = endless
        code = main(["files", f"127.0.0.1:{running.port}", "get", "a.map", "--out", str(tmp_path / "b.map")])
    assert code == EXIT_CONNECTION and "download stopped" in capsys.readouterr().err
    assert left_in(tmp_path) == []


def test_a_file_that_never_ends_times_out_and_nothing_is_saved(tmp_path: Path) -> None:
    server = file_server((file_entry("a.map", 100_000),))
    server.handlers["getFile"] = lambda s, a: [FileChunk(0, "a.map", b"x" * 1000).encode()]  # then silence

    async def body(c: AriaClient) -> None:
        with pytest.raises(ClientTimeout, match="stalled"):
            await download_file(c, "a.map", tmp_path / "a.map", timeout=0.5)

    with_client(server, body)
    assert left_in(tmp_path) == []


def test_a_file_answered_under_another_name_is_refused(tmp_path: Path) -> None:
    server = file_server((file_entry("a.map"),))
    server.handlers["getFile"] = lambda s, a: [FileChunk(0, "../../etc/passwd", b"x").encode()]

    async def body(c: AriaClient) -> None:
        with pytest.raises(MalformedReply, match=r"answered 'a\.map' with '\.\./\.\./etc/passwd'"):
            await download_file(c, "a.map", tmp_path / "a.map")

    with_client(server, body)
    assert left_in(tmp_path) == []


def test_an_existing_file_is_never_replaced_by_a_failed_download(tmp_path: Path) -> None:
    (tmp_path / "a.map").write_text("precious")
    server = file_server((file_entry("a.map", 100),))
    server.handlers["getFile"] = endless

    async def body(c: AriaClient) -> None:
        with pytest.raises(SizeLie):
            await download_file(c, "a.map", tmp_path / "a.map", overwrite=True)

    with_client(server, body)
    assert left_in(tmp_path) == ["a.map"] and (tmp_path / "a.map").read_text() == "precious"


def refuse_after(count: int, code: int) -> Callable[[ServerSide, bytes], list[bytes] | None]:
    """A plain putFile that takes ``count`` data packets, then answers ``code`` to each one after."""
    seen = [0]

    def handle(side: ServerSide, args: bytes) -> list[bytes] | None:
        request = PutFileRequest.decode(args)
        if request.command == 1:
            seen[0] += 1
            if seen[0] > count:
                return [PutFileReply(code, request.name).encode()]
        if request.command == 2:
            return [PutFileReply(0, request.name).encode()]
        return None

    return handle


def test_an_upload_refused_half_way_is_a_clear_error(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    local = tmp_path / "big.bin"
    local.write_bytes(b"y" * 3_000_000)
    server = file_server()
    server.handlers["putFile"] = refuse_after(20, 8)

    async def body(c: AriaClient) -> None:
        with pytest.raises(
            Refused, match="stalled for 15 s and another client took the file over"
        ) as refused:
            await upload_file(c, local, "big.bin", keep_time=False)
        assert refused.value.code == 8

    with_client(server, body)
    sent = [PutFileRequest.decode(r.args).command for r in server.received if r.name == "putFile"]
    # Cancelled: the last word is "cancel". (A streamed upload's "done" may already be in the loopback
    # socket's megabytes of buffer when a busy server's refusal arrives, so it is not asserted absent.)
    assert sent[-1] == 3, sent[-3:]
    with ServerThread(file_server()) as running:
        running.handlers["putFile"] = refuse_after(5, 9)
        code = main(["files", f"127.0.0.1:{running.port}", "put", str(local), "big.bin", "--force"])
    assert code == EXIT_REFUSED and "no upload of that file under way" in capsys.readouterr().err


def test_an_interleaved_upload_refused_half_way_is_a_clear_error(tmp_path: Path) -> None:
    local = tmp_path / "big.bin"
    local.write_bytes(b"y" * 200_000)
    server = file_server()
    answers = iter([10, 10, 10, 5])
    server.handlers["putFileInterleaved"] = lambda s, a: [PutFileReply(next(answers, 9), "big.bin").encode()]

    async def body(c: AriaClient) -> None:
        with pytest.raises(Refused, match="could not write its temporary file"):
            await upload_file(c, local, "big.bin", interleaved=True, keep_time=False)

    with_client(server, body)


def test_a_default_folder_outside_the_robots_folder_is_refused() -> None:
    server = file_server()
    server.handlers["getDefaultUploadDownloadDir"] = lambda s, a: [b"../../etc\0"]

    async def body(c: AriaClient) -> None:
        with pytest.raises(UnsafeName, match="default folder cannot be used"):
            await default_folder(c)

    with_client(server, body)


def test_a_scan_named_like_a_path_downloads_nothing_and_ends_nothing(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    server = file_server()
    server.handlers["mappingStatus"] = lambda s, a: [b"../../etc/cron.d/evil\0"]
    server.handlers["mappingEnd"] = lambda s, a: [b"\x00\x00"]
    out = tmp_path / "scans"
    out.mkdir()
    with ServerThread(server) as running:
        code = main(["scan", f"127.0.0.1:{running.port}", "stop", "--download", str(out)])
        names = running.names()
    assert code == EXIT_CONNECTION and "not a plain file name" in capsys.readouterr().err
    assert "mappingEnd" not in names and left_in(out) == [] and left_in(tmp_path) == ["scans"]


def test_a_server_without_files_greys_everything_with_the_reason(capsys) -> None:  # type: ignore[no-untyped-def]
    with ServerThread(TestServer()) as running:
        code = main(["files", f"127.0.0.1:{running.port}", "ls"])
        scan = main(["scan", f"127.0.0.1:{running.port}", "status"])
    err = capsys.readouterr().err
    assert code == scan == EXIT_UNSUPPORTED
    assert "does not let its files be listed" in err and "does not say whether it is scanning" in err
    with pytest.raises(NotSupported):
        raise NotSupported("x")

"""Files on the robot and scanning for a map, against the simulator over loopback.

Every ArServerFileUtils and ArServerHandlerMapping request: the client functions the window and the
command line use (list, download, upload in each variant, delete, default folder, scan start / status /
loop tags / stop / broadcast), and the simulator's own answers as ARIA gives them (codes, silences,
packet series), asked for with raw requests where the client would pick another variant.
"""

from __future__ import annotations

import asyncio
import os
from collections.abc import Awaitable, Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from rtmu.client.connection import AriaClient
from rtmu.client.download import LocalFileError, download_file
from rtmu.client.errors import NotSupported
from rtmu.client.remote_files import Refused, default_folder, delete_file, list_folder, unavailable
from rtmu.client.scan import ScanWatch, scan_status, scan_unavailable, start_scan, stop_scan, tag_loop
from rtmu.client.upload import upload_file
from rtmu.protocol.payloads.files import (
    DirListing,
    DirListingPacket,
    FileChunk,
    GetFileRequest,
    PutFileCommand,
    PutFileInterleavedRequest,
    PutFileReply,
    PutFileRequest,
    PutFileWithTimestampInterleavedRequest,
)
from rtmu.protocol.payloads.mapping import MappingEndReply
from rtmu.sim import SimConfig, SimThread
from rtmu.values.target import Target
from simulators import running

from .servers import run


@pytest.fixture
def files(tmp_path: Path) -> Path:
    root = tmp_path / "robot"
    (root / "maps").mkdir(parents=True)
    (root / "maps" / "Office.map").write_bytes(b"2D-Map\n" * 5000)
    (root / "notes.txt").write_text("hello\n")
    (root / ".hidden").write_text("never listed")
    return root


@pytest.fixture
def sim(files: Path) -> Iterator[SimThread]:
    with running(files_dir=files, files_default_dir="maps") as s:
        yield s


def with_client(sim: SimThread, body: Callable[[AriaClient], Awaitable[Any]], timeout: float = 60.0) -> Any:
    async def main() -> Any:
        client = AriaClient()
        await client.connect(Target("127.0.0.1", sim.port), timeout=10)
        try:
            return await body(client)
        finally:
            await client.disconnect()

    return run(main(), timeout)


def test_every_feature_is_offered_and_the_default_folder_named(sim: SimThread) -> None:
    async def body(c: AriaClient) -> Any:
        return unavailable(c), scan_unavailable(c), await default_folder(c)

    assert with_client(sim, body) == ({}, {}, "maps")


def test_without_a_default_folder_the_feature_is_greyed_with_the_reason(files: Path) -> None:
    with SimThread(SimConfig(port=0, files_dir=files)) as plain:

        async def body(c: AriaClient) -> Any:
            with pytest.raises(NotSupported, match="names no default folder"):
                await default_folder(c)
            return unavailable(c)

        missing = with_client(plain, body)
    assert list(missing) == ["default_folder"] and "getDefaultUploadDownloadDir" in missing["default_folder"]


def test_listing_both_ways(sim: SimThread) -> None:
    async def body(c: AriaClient) -> Any:
        top = await list_folder(c, "")
        maps = await list_folder(c, "maps/")
        single = DirListing.decode((await c.request_once("getDirListing", "maps")).payload)
        multi = (await c.request_once("getDirListingMultiplePackets", "maps")).payloads
        return top, maps, single, multi

    top, maps, single, multi = with_client(sim, body)
    assert [(e.name, e.is_folder) for e in top.sorted()] == [("maps", True), ("notes.txt", False)]
    assert top.source == "getDirListingMultiplePackets"
    assert [(e.name, e.size) for e in maps.entries] == [("Office.map", 35000)]
    assert single.code == 0 and [e.name for e in single.entries] == ["Office.map"]
    assert multi[-1] == b"" and DirListingPacket.decode(multi[0]).entries == single.entries


@pytest.mark.parametrize(
    ("folder", "code"), [("../", 1), ("~", 1), ("/etc", 1), ("nope", 2), ("notes.txt", 2)]
)
def test_the_simulator_refuses_listings_as_aria_does(sim: SimThread, folder: str, code: int) -> None:
    async def body(c: AriaClient) -> Any:
        one = DirListing.decode((await c.request_once("getDirListing", folder)).payload)
        many = (await c.request_once("getDirListingMultiplePackets", folder)).payloads
        return one, many

    one, many = with_client(sim, body)
    assert (one.code, one.folder) == (code, folder)
    assert [DirListingPacket.decode(p) for p in many] == [
        DirListingPacket(code, folder),
        DirListingPacket(end=True),
    ]


def test_list_folder_says_the_robots_refusal(sim: SimThread) -> None:
    async def body(c: AriaClient) -> None:
        with pytest.raises(Refused, match="no such folder") as refused:
            await list_folder(c, "nope")
        assert refused.value.code == 2

    with_client(sim, body)


def test_download_both_variants_and_case_insensitive_names(
    sim: SimThread, files: Path, tmp_path: Path
) -> None:
    out = tmp_path / "here"
    out.mkdir()
    original = (files / "maps" / "Office.map").read_bytes()
    os.utime(files / "maps" / "Office.map", (1_700_000_000, 1_700_000_000))
    seen: list[tuple[int, int | None]] = []

    async def body(c: AriaClient) -> Any:
        stamped = await download_file(
            c, "maps/office.MAP", out / "a.map", progress=lambda d, t: seen.append((d, t))
        )
        unlisted = await download_file(c, "MAPS/office.map", out / "b.map")  # listed only by its exact name
        plain = (await c.request_once(GetFileRequest("maps/office.map"))).payloads
        return stamped, unlisted, plain

    stamped, unlisted, plain = with_client(sim, body)
    assert (out / "b.map").read_bytes() == original and unlisted.listed_size is None
    assert (out / "a.map").read_bytes() == original and stamped.size == len(original) == stamped.listed_size
    assert stamped.mtime == 1_700_000_000 and int((out / "a.map").stat().st_mtime) == 1_700_000_000
    assert seen[-1] == (len(original), len(original))
    assert sorted(p.name for p in out.iterdir()) == ["a.map", "b.map"]  # no temporary file left
    umask = os.umask(0)
    os.umask(umask)
    assert (out / "a.map").stat().st_mode & 0o777 == 0o666 & ~umask  # as any new file, not private
    chunks = [FileChunk.decode(p) for p in plain]
    assert chunks[-1].end and chunks[-2].end_of_file and b"".join(c.data for c in chunks) == original
    assert all(len(c.data) <= 30_000 for c in chunks)


@pytest.mark.parametrize(
    ("name", "code"), [("nope.txt", 2), ("", 2), ("/etc/passwd", 2), ("../notes.txt", 2), ("maps", 4)]
)
def test_the_simulator_refuses_files_as_aria_does(sim: SimThread, name: str, code: int) -> None:
    async def body(c: AriaClient) -> Any:
        return (await c.request_once(GetFileRequest(name))).payloads

    payloads = with_client(sim, body)
    assert [FileChunk.decode(p) for p in payloads] == [FileChunk(code, name), FileChunk(end=True)]


def test_a_refused_download_writes_nothing(sim: SimThread, tmp_path: Path) -> None:
    async def body(c: AriaClient) -> None:
        with pytest.raises(Refused, match="lists no file"):
            await download_file(c, "maps/nope.map", tmp_path / "x.map")
        with pytest.raises(Refused, match="no such file"):
            await download_file(c, "maps/nope.map", tmp_path / "x.map", size=10)  # straight to getFile
        with pytest.raises(Refused, match="is a folder"):
            await download_file(c, "maps", tmp_path / "x.map")
        (tmp_path / "taken.map").write_text("mine")
        with pytest.raises(LocalFileError, match="already exists"):
            await download_file(c, "maps/office.map", tmp_path / "taken.map")

    with_client(sim, body)
    assert sorted(p.name for p in tmp_path.iterdir() if p.name != "robot") == ["taken.map"]
    assert (tmp_path / "taken.map").read_text() == "mine"


@pytest.mark.parametrize("interleaved", [None, True], ids=["plain", "interleaved"])
@pytest.mark.parametrize("keep_time", [True, False], ids=["timestamp", "no-timestamp"])
def test_upload_each_variant(
    sim: SimThread, files: Path, tmp_path: Path, interleaved: bool | None, keep_time: bool
) -> None:
    data = os.urandom(100_001)
    local = tmp_path / "up.bin"
    local.write_bytes(data)
    os.utime(local, (1_600_000_000, 1_600_000_000))
    seen: list[int] = []

    async def body(c: AriaClient) -> Any:
        return await upload_file(
            c,
            local,
            "maps/up.bin",
            interleaved=interleaved,
            keep_time=keep_time,
            progress=lambda d, t: seen.append(d),
        )

    done = with_client(sim, body)
    assert (files / "maps" / "up.bin").read_bytes() == data and done.size == len(data)
    assert seen[-1] == len(data) and len(seen) == 4
    kept = int((files / "maps" / "up.bin").stat().st_mtime) == 1_600_000_000
    # ARIA serves putFileWithTimestampInterleaved with putFileInterleaved: the time is dropped
    assert kept == (keep_time and interleaved is None)
    assert not [p for p in (files / "maps").iterdir() if p.name.startswith(".")]  # no temporary file left


def test_an_empty_file_uploads(sim: SimThread, files: Path, tmp_path: Path) -> None:
    (tmp_path / "empty").write_bytes(b"")
    with_client(sim, lambda c: upload_file(c, tmp_path / "empty", "empty"))
    assert (files / "empty").read_bytes() == b""


def test_upload_refusals(sim: SimThread, tmp_path: Path) -> None:
    local = tmp_path / "up.bin"
    local.write_bytes(b"x" * 10)

    async def body(c: AriaClient) -> None:
        for interleaved in (None, True):
            with pytest.raises(Refused, match="no such folder") as refused:
                await upload_file(c, local, "nofolder/up.bin", interleaved=interleaved)
            assert refused.value.code == 3

    with_client(sim, body)


def test_another_client_uploading_the_same_file_is_refused_with_7(sim: SimThread, tmp_path: Path) -> None:
    local = tmp_path / "up.bin"
    local.write_bytes(b"x" * 10)

    async def body(first: AriaClient) -> None:
        reply = await first.request_once(PutFileInterleavedRequest(PutFileCommand.START, "maps/same.bin"))
        assert PutFileReply.decode(reply.payload) == PutFileReply(10, "maps/same.bin")
        second = AriaClient()
        await second.connect(Target("127.0.0.1", sim.port))
        try:
            with pytest.raises(Refused, match="another client is uploading") as refused:
                await upload_file(second, local, "MAPS/same.bin")
            assert refused.value.code == 7
            # a data packet for a put the robot does not have: 9
            answer = await second.request_once(PutFileInterleavedRequest(PutFileCommand.DATA, "other", b"x"))
            assert PutFileReply.decode(answer.payload).code == 9
        finally:
            await second.disconnect()
        cancel = await first.request_once(PutFileInterleavedRequest(PutFileCommand.CANCEL, "maps/same.bin"))
        assert PutFileReply.decode(cancel.payload).code == 11

    with_client(sim, body)


def test_the_simulator_refuses_an_upload_that_would_leave_its_folder(sim: SimThread, files: Path) -> None:
    async def body(c: AriaClient) -> list[int]:
        codes = []
        for name in ("maps/..", "maps/", "../x", ""):
            reply = await c.request_once(
                PutFileWithTimestampInterleavedRequest(PutFileCommand.START, name, mtime=1)
            )
            codes.append(PutFileReply.decode(reply.payload).code)
        return codes

    assert with_client(sim, body) == [4, 4, 3, 4]
    assert sorted(p.name for p in files.parent.iterdir()) == ["robot"]


def test_plain_put_file_answers_only_the_end(sim: SimThread, files: Path) -> None:
    async def body(c: AriaClient) -> Any:
        heard: list[bytes] = []
        c.listen("putFile", lambda p: heard.append(p.payload))
        c.send(PutFileRequest(PutFileCommand.START, "quiet.txt"))
        c.send(PutFileRequest(PutFileCommand.DATA, "quiet.txt", b"abc"))
        c.send(PutFileRequest(PutFileCommand.DONE, "quiet.txt"))
        for _ in range(200):
            if heard:
                break
            await asyncio.sleep(0.01)
        await c.request_once("getDirListing", "")  # anything still due has arrived by now
        return heard

    assert [PutFileReply.decode(p) for p in with_client(sim, body)] == [PutFileReply(0, "quiet.txt")]
    assert (files / "quiet.txt").read_bytes() == b"abc"


def test_delete(sim: SimThread, files: Path) -> None:
    async def body(c: AriaClient) -> None:
        await delete_file(c, "NOTES.txt")
        for name, words, code in (("notes.txt", "no such file", 2), ("maps", "no such file", 2)):
            with pytest.raises(Refused, match=words) as refused:
                await delete_file(c, name)
            assert refused.value.code == code

    with_client(sim, body)
    assert not (files / "notes.txt").exists() and (files / "maps").is_dir()


def test_a_scan_start_status_loop_stop_and_broadcasts(sim: SimThread, files: Path, tmp_path: Path) -> None:
    heard: list[str] = []

    async def body(c: AriaClient) -> Any:
        watch = ScanWatch(c, lambda s: heard.append(s.file_name))
        assert not (await watch.start()).scanning
        assert await start_scan(c, "Lab") == "lab.2d"
        status = await scan_status(c)
        with pytest.raises(Refused, match="already running") as again:
            await start_scan(c, "other")
        assert again.value.code == 1
        assert await tag_loop(c, start=True, tag="1") and await tag_loop(c, start=False, tag="1")
        for _ in range(1000):  # a tag is written at the logger's next look, within 100 ms of robot time
            if "loop stop 1\n" in (files / "lab.2d").read_text():
                break
            await asyncio.sleep(0.01)
        assert await stop_scan(c) == "lab.2d"
        with pytest.raises(Refused, match="no scan is running") as none:
            await stop_scan(c)
        assert none.value.code == 1
        raw_end = await c.request_once("mappingEnd")
        got = await download_file(c, "lab.2d", tmp_path / "lab.2d")
        await c.request_once("getDirListing", "")
        return status, raw_end.payload, got

    status, raw_end, got = with_client(sim, body)
    assert (status.name, status.file_name) == ("lab", "lab.2d")
    assert raw_end == b"\x01" and MappingEndReply.decode(raw_end).code == 1
    assert heard == ["lab.2d", ""]
    text = (tmp_path / "lab.2d").read_text()
    assert text.startswith("LaserOdometryLog\n") and text.endswith("# End of log\n")
    assert "loop start 1\n" in text and "loop stop 1\n" in text
    assert got.size == (files / "lab.2d").stat().st_size


@pytest.mark.parametrize("name", ["../escape", "a/b", ".hidden", "tab\there"])
def test_a_scan_name_that_would_leave_the_folder_is_refused(sim: SimThread, files: Path, name: str) -> None:
    async def body(c: AriaClient) -> bytes:
        return (await c.request_once("mappingStart", name)).payload

    assert with_client(sim, body) == b"\x02"
    assert sorted(p.name for p in files.iterdir()) == [".hidden", "maps", "notes.txt"]
    assert sorted(p.name for p in files.parent.iterdir()) == ["robot"]


def test_the_default_files_folder_is_temporary_and_goes_with_the_simulator() -> None:
    from rtmu.sim.files_folder import files_folder

    with SimThread(SimConfig(port=0)) as s:
        assert s.server is not None
        folder = files_folder(s.server)
        root = folder.root
        assert root.is_dir() and folder.temporary is not None
        with_client(s, lambda c: start_scan(c, "x"))
        assert (root / "x.2d").is_file()
        folder.temporary.cleanup()
    assert not root.exists()


def test_a_cancelled_transfer_leaves_nothing_behind(sim: SimThread, files: Path, tmp_path: Path) -> None:
    (files / "big.bin").write_bytes(os.urandom(3_000_000))
    local = tmp_path / "up.bin"
    local.write_bytes(os.urandom(3_000_000))

    async def cancelled(start: Callable[[Callable[[int, int | None], None]], Awaitable[Any]]) -> None:
        first = asyncio.Event()
        task = asyncio.ensure_future(start(lambda done, total: first.set()))
        await first.wait()
        task.cancel()
        with pytest.raises(asyncio.CancelledError):
            await task

    async def body(c: AriaClient) -> None:
        await cancelled(lambda p: download_file(c, "big.bin", tmp_path / "big.bin", progress=p))
        await cancelled(lambda p: upload_file(c, local, "maps/up.bin", interleaved=True, progress=p))
        await list_folder(c, "maps")  # the connection goes on

    with_client(sim, body)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["robot", "up.bin"]
    assert sorted(p.name for p in (files / "maps").iterdir()) == ["Office.map"]  # temporary file dropped


def test_scan_progress_reads_time_and_distance() -> None:
    from rtmu.client.scan import ScanProgress

    progress = ScanProgress(100.0)
    for i in range(11):
        progress.feed(i * 1420.0, 0.0, 100.0 + i * 10.2)
    progress.feed(90_000.0, 0.0, 202.0)  # a jump (relocalised) is not driving
    assert progress.text() == "1:42, 14.2 m driven"

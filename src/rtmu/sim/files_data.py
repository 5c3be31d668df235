"""ARIA's file services for the simulator (``ROWS`` + ``HANDLERS``, a data module of :mod:`.profiles`).

Served as ARIA 2.9.1's ``ArServerFileLister``, ``ArServerFileToClient``, ``ArServerFileFromClient`` and
``ArServerDeleteFileOnServer`` serve them (rooted in :mod:`.files_folder`): the same return codes, the
same answers and silences (a plain ``putFile`` answers only refusals and the end; the timestamped
interleaved one ignores its timestamp, as ARIA's does), the same packet sizes. A file is sent a packet at
a time as the client reads it, after the files it asked for before. Where ARIA would write outside its
folder (an upload named ``dir/..``) the simulator refuses with code 4. ``getDefaultUploadDownloadDir`` is
listed only when the simulator is given a default folder (:func:`add_default_folder`), as ARIA does.
Names, groups and flags are ARIA's; descriptions are our own words.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Final
from weakref import WeakKeyDictionary

from rtmu.protocol.datalist import DataEntry, DataList
from rtmu.protocol.errors import ProtocolError
from rtmu.protocol.fields import FieldReader
from rtmu.protocol.packet import MAX_PAYLOAD
from rtmu.protocol.payloads.files import (
    FILE_CHUNK,
    DefaultUploadDownloadDir,
    DeleteFileCode,
    DeleteFileReply,
    DirEntry,
    DirListing,
    DirListingPacket,
    FileChunk,
    GetFileCode,
    ListingCode,
    PutFileCode,
    PutFileCommand,
    PutFileReply,
    PutFileRequest,
    PutFileWithTimestampRequest,
    TimestampedFileChunk,
)

from .catalogue import Row
from .files_folder import NAME_LIMIT, FilesFolder, Upload, disk, files_folder, fold
from .handlers import Call, Handler, Reply

if TYPE_CHECKING:
    from .context import SimClient

log = logging.getLogger("rtmu.sim.files")

Answer = Callable[[int], tuple[bytes]]
TAKEOVER_S: Final = 15.0
"""An upload idle this long may be taken over by another client starting the same file (ARIA's 15 s)."""
_FILES = "FileAccess"
_SLOW = "SLOW_PACKET"
_COMPLEX = "DO_NOT_FORWARD|RETURN_COMPLEX|SLOW_PACKET"

ROWS: tuple[Row, ...] = (
    ("getDirListing", "Lists one folder of the robot's shared folder in one packet", "string: folder",
     "ubyte2: code; string: folder; folders then files (name, access time, modification time, size)",
     _FILES, f"RETURN_SINGLE|{_SLOW}"),
    ("getDirListingMultiplePackets", "Lists one folder of the robot's shared folder over several packets",
     "string: folder", "ubyte2: code; string: folder; ubyte2: count; entries (byte: 1 folder, 2 file; name; "
     "access time; modification time; size); an empty packet ends the listing",
     _FILES, f"RETURN_UNTIL_EMPTY|{_SLOW}"),
    ("getFile", "Sends one file of the robot's shared folder", "string: file; ubyte2: 0",
     "ubyte2: code; string: file; ubyte4: bytes and the bytes, until a packet of none; then an empty packet",
     _FILES, f"RETURN_UNTIL_EMPTY|{_SLOW}"),
    ("getFileWithTimestamp", "Sends one file of the robot's shared folder with its modification time",
     "string: file; ubyte2: 0", "as getFile, with byte4: modification time after each byte count",
     _FILES, f"RETURN_UNTIL_EMPTY|{_SLOW}"),
    ("putFile", "Receives a file into the robot's shared folder", "ubyte2: command; string: file; data",
     "ubyte2: code; string: file (refusals and the result only)", _FILES, _COMPLEX),
    ("putFileInterleaved", "Receives a file, answering every packet", "ubyte2: command; string: file; data",
     "ubyte2: code; string: file", _FILES, f"DO_NOT_FORWARD|RETURN_SINGLE|{_SLOW}"),
    ("putFileWithTimestamp", "Receives a file and keeps the modification time sent with it",
     "ubyte2: command; string: file; byte4: time with the start; data",
     "ubyte2: code; string: file (refusals and the result only)", _FILES, _COMPLEX),
    ("putFileWithTimestampInterleaved", "Receives a file with a modification time, answering every packet",
     "ubyte2: command; string: file; byte4: time with the start; data", "ubyte2: code; string: file",
     _FILES, f"DO_NOT_FORWARD|RETURN_SINGLE|{_SLOW}"),
    ("deleteFile", "Deletes one file of the robot's shared folder", "string: file",
     "ubyte2: code; string: file", _FILES, f"RETURN_SINGLE|{_SLOW}"),
)  # fmt: skip
DEFAULT_FOLDER_ROW: Row = (
    "getDefaultUploadDownloadDir", "Names the folder to offer first for uploads and downloads", "none",
    "string: folder", _FILES, f"RETURN_SINGLE|{_SLOW}",
)  # fmt: skip


def add_default_folder(datalist: DataList, handlers: dict[str, Handler], folder: str) -> None:
    """List ``getDefaultUploadDownloadDir`` naming ``folder`` (at the end of the list, as ARIA adds data)."""
    name, description, args, returns, group, flags = DEFAULT_FOLDER_ROW
    if name not in datalist:
        number = max((e.number for e in datalist), default=255) + 1
        datalist.add(DataEntry(number, name, description, args, returns, group, flags))

    def answer(call: Call) -> Iterable[Reply]:
        return (DefaultUploadDownloadDir(folder).encode(),)

    handlers[name] = answer


def _string_arg(call: Call) -> str:
    """The first string argument as ARIA reads it: missing is ``""``, cut at 2047 characters."""
    return FieldReader(call.args).string("name", default="")[:NAME_LIMIT]


def _outside(name: str) -> bool:
    """ARIA's own test, on the name after leading blanks: an absolute path, ``~``, or ``..`` anywhere."""
    stripped = name.lstrip(" \t\n\v\f\r")
    return stripped.startswith(("/", "~", "\\")) or ".." in stripped


# -- listings ---------------------------------------------------------------------------------------------
def _listed_folder(call: Call) -> tuple[str, Path | None, int]:
    asked = _string_arg(call)
    if _outside(asked):
        return asked, None, ListingCode.OUTSIDE
    folder = files_folder(call.server)
    relative = disk(asked.lstrip(" \t\n\v\f\r").replace("\\", "/"))
    path = folder.root / relative
    if not path.is_dir() or not folder.inside(path):
        return asked, None, ListingCode.NO_FOLDER
    return asked, path, ListingCode.OK


def _dir_listing(call: Call) -> Iterable[Reply]:
    asked, path, code = _listed_folder(call)
    if path is None:
        return (DirListing(code, asked).encode(),)
    entries = sorted(files_folder(call.server).entries(path), key=lambda e: (not e.is_folder, fold(e.name)))
    kept: list[DirEntry] = []
    room = MAX_PAYLOAD - len(asked) - 7
    for entry in entries:  # ARIA's packet silently stops growing when full
        room -= len(entry.name) + 13
        if room < 0:
            break
        kept.append(entry)
    return (DirListing(code, asked, tuple(kept)).encode(),)


def _dir_listing_multiple(call: Call) -> Iterable[Reply]:
    asked, path, code = _listed_folder(call)
    if path is None:
        return (DirListingPacket(code, asked).encode(), b"")
    packets: list[bytes] = []
    batch: list[DirEntry] = []
    used = len(asked) + 5
    for entry in files_folder(call.server).entries(path):
        if used + len(entry.name) + 12 >= MAX_PAYLOAD:  # ARIA's rule for starting a new packet
            packets.append(DirListingPacket(code, asked, tuple(batch)).encode())
            batch, used = [], len(asked) + 5
        batch.append(entry)
        used += len(entry.name) + 14
    packets.append(DirListingPacket(code, asked, tuple(batch)).encode())
    return (*packets, b"")


# -- getFile ---------------------------------------------------------------------------------------------
_SENDING: WeakKeyDictionary[SimClient, asyncio.Task[None]] = WeakKeyDictionary()
"""Each client's file being sent: the next one it asks for waits for it (ARIA answers in order)."""


def _get_file(call: Call) -> Iterable[Reply]:
    stamped = call.name == "getFileWithTimestamp"
    chunk = TimestampedFileChunk if stamped else FileChunk
    raw = _string_arg(call)
    folder = files_folder(call.server)
    path = folder.match(raw)
    if path is None:
        return (chunk(GetFileCode.NO_FILE, raw).encode(), b"")
    if _outside(folder.relative(path)):
        return (chunk(GetFileCode.OUTSIDE, raw).encode(), b"")
    before = _SENDING.get(call.session)
    task = asyncio.get_running_loop().create_task(
        _send_file(call.session, call.number, path, raw, chunk, before)
    )
    _SENDING[call.session] = task
    return ()


async def _send_file(
    session: SimClient,
    number: int,
    path: Path,
    raw: str,
    chunk: type[FileChunk],
    before: asyncio.Task[None] | None,
) -> None:
    if before is not None:
        with contextlib.suppress(Exception, asyncio.CancelledError):
            await before
    try:
        mtime = max(-(2**31), min(int(path.stat().st_mtime), 2**31 - 1))
        with path.open("rb") as f:
            while not session.closed:
                data = f.read(FILE_CHUNK)
                if not data:
                    break
                session.send(number, chunk(GetFileCode.OK, raw, data, mtime).encode())
                await session.writer.drain()  # as fast as the client reads, and no faster
                await asyncio.sleep(0)  # a socket that takes everything never makes drain() wait
    except OSError:  # a folder, or unreadable: ARIA's read fails and says 4
        session.send(number, chunk(GetFileCode.READ_ERROR, raw).encode())
        session.send(number, b"")
        return
    except (ConnectionError, RuntimeError):
        return
    if not session.closed:
        session.send(number, chunk(GetFileCode.OK, raw, b"", mtime).encode())
        session.send(number, b"")


# -- putFile ---------------------------------------------------------------------------------------------
def _put_file(call: Call) -> Iterable[Reply]:
    interleaved = call.name.endswith("Interleaved")
    stamped = call.name == "putFileWithTimestamp"  # ARIA serves the interleaved one without its timestamp
    try:
        request = (PutFileWithTimestampRequest if stamped else PutFileRequest).decode(call.args)
    except ProtocolError:
        return ()  # ARIA would read zeros and garbage; a simulator ignores it
    raw = request.name[:NAME_LIMIT]
    folder = files_folder(call.server)

    def answer(code: int) -> tuple[bytes]:
        return (PutFileReply(code, raw).encode(),)

    if request.command == PutFileCommand.START:
        return _start(call, folder, raw, request.mtime if stamped else None, interleaved, answer)
    upload = folder.uploads.get(raw)
    if request.command not in (PutFileCommand.DATA, PutFileCommand.DONE, PutFileCommand.CANCEL):
        return ()
    if upload is None:
        return answer(PutFileCode.UNKNOWN_PUT)
    if upload.client != call.session.ident:
        return ()  # ARIA ignores another client's packets for a file (it answered their start already)
    upload.last_activity = time.monotonic()
    if request.command == PutFileCommand.DATA:
        upload.file.write(request.data)
        return answer(PutFileCode.NEXT) if interleaved else ()
    del folder.uploads[raw]
    upload.file.close()
    if request.command == PutFileCommand.CANCEL:
        upload.temp.unlink(missing_ok=True)
        return answer(PutFileCode.CANCELLED) if interleaved else ()
    try:
        os.replace(upload.temp, upload.final)
        if upload.mtime is not None:
            os.utime(upload.final, (upload.mtime, upload.mtime))
    except OSError:
        upload.temp.unlink(missing_ok=True)
        return answer(PutFileCode.CANNOT_MOVE)
    return answer(PutFileCode.DONE)


def _start(
    call: Call, folder: FilesFolder, raw: str, mtime: int | None, interleaved: bool, answer: Answer
) -> Iterable[Reply]:
    directory, _, name = raw.replace("\\", "/").rpartition("/")
    if not raw or not name or name in (".", ".."):
        return answer(PutFileCode.BAD_NAME)
    target = folder.root if not directory else folder.match(directory)
    if target is None or not target.is_dir():
        return answer(PutFileCode.BAD_FOLDER)
    existing = folder.find(sorted(os.listdir(target)), fold(name))
    final = target / (existing or disk(name))
    now = time.monotonic()
    for other_raw, other in list(folder.uploads.items()):
        if fold(str(other.final)) != fold(str(final)):
            continue
        if now - other.last_activity <= TAKEOVER_S:
            return answer(PutFileCode.BUSY)
        if not interleaved:
            call.server.broadcast("putFile", PutFileReply(PutFileCode.TAKEN_OVER, other_raw).encode())
        del folder.uploads[other_raw]
        other.file.close()
        other.temp.unlink(missing_ok=True)
    temp = folder.temp_file()
    try:
        handle = temp.open("wb")
    except OSError:
        return answer(PutFileCode.CANNOT_WRITE)
    folder.uploads[raw] = Upload(final, temp, handle, call.session.ident, now, mtime)
    return answer(PutFileCode.NEXT) if interleaved else ()


# -- deleteFile ------------------------------------------------------------------------------------------
def _delete_file(call: Call) -> Iterable[Reply]:
    raw = _string_arg(call)
    folder = files_folder(call.server)
    path = folder.match(raw)
    if path is None:
        return (DeleteFileReply(DeleteFileCode.NO_FILE, raw).encode(),)
    if _outside(folder.relative(path)):
        return (DeleteFileReply(DeleteFileCode.OUTSIDE, raw).encode(),)
    try:
        path.unlink()  # a folder cannot be unlinked: ARIA says 2
    except OSError:
        return (DeleteFileReply(DeleteFileCode.NO_FILE, raw).encode(),)
    return (DeleteFileReply(DeleteFileCode.DELETED, raw).encode(),)


HANDLERS: dict[str, Handler] = {
    "getDirListing": _dir_listing,
    "getDirListingMultiplePackets": _dir_listing_multiple,
    "getFile": _get_file,
    "getFileWithTimestamp": _get_file,
    "putFile": _put_file,
    "putFileInterleaved": _put_file,
    "putFileWithTimestamp": _put_file,
    "putFileWithTimestampInterleaved": _put_file,
    "deleteFile": _delete_file,
}

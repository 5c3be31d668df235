"""Download one file from the robot (``getFile``) straight to disk, never whole in memory.

The file is written to a hidden temporary file beside the destination and only renamed to the
destination's name once the robot said the file is complete, so an error, a cancel or a dead link
leaves nothing under that name (and the temporary file is removed). Disk writes run off the network
loop in batches of :data:`WRITE_BATCH`; what waits unread is bounded by the connection
(:data:`BACKLOG`), so memory stays flat whatever the file's size.

ARIA sends no size with a file: the size comes from the folder's listing, asked for first where the
robot offers one. It gives progress its total and bounds the download: a robot that sends more than it
listed (plus :data:`GROWTH_SLACK`, for a scan log still growing) is cut off with a clear error, as is
one that stalls for the timeout between two packets. ARIA cannot stop a ``getFile`` once asked, so a
cancelled download's remaining packets are read and dropped.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import secrets
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO, Final

from ..base.exit_codes import EXIT_USAGE
from ..base.textsafe import visible
from ..protocol.errors import ProtocolError
from ..protocol.payloads.files import (
    GET_FILE_WORDS,
    DirEntry,
    EntryKind,
    FileChunk,
    GetFileCode,
    GetFileRequest,
    GetFileWithTimestampRequest,
    TimestampedFileChunk,
    code_words,
)
from .connection import REPLY_TIMEOUT, AriaClient
from .errors import ClientError, MalformedReply
from .remote_files import Refused, closing_stream, data_for, find_entry, malformed, offers, remote_path

WRITE_BATCH: Final = 1 << 20
"""Bytes gathered before one write (off the network loop)."""
BACKLOG: Final = 32 << 20
"""Bytes received but not yet written that may wait; past this the download fails (the disk is far
slower than the link)."""
GROWTH_SLACK: Final = 1 << 20
"""Bytes a file may have grown since it was listed (a scan log while scanning) before the robot is
taken to be lying about its size."""
MAX_DOWNLOAD: Final = 1 << 32
"""Without a listed size: at most this many bytes (ARIA's listing sizes are 32-bit)."""

Progress = Callable[[int, int | None], None]
"""``progress(bytes so far, total or None)``, called on the network loop after each packet."""


class LocalFileError(ClientError):
    """The destination on this computer cannot be used (it exists, its folder is missing …): exit 2."""

    exit_code = EXIT_USAGE
    kind = "local"


class SizeLie(MalformedReply):
    """The robot sent more bytes than it listed for the file (or than any file may have)."""


@dataclass(frozen=True, slots=True)
class Transfer:
    """A finished transfer: ``size`` bytes between ``remote`` and ``local`` in ``seconds``."""

    remote: str
    local: Path
    size: int
    seconds: float
    listed_size: int | None = None
    """What the listing said (None: not listed); a download that differs from it says so."""
    mtime: int | None = None
    """The file's modification time as the robot gave it (and set on the local file), if it did."""

    @property
    def rate(self) -> float:
        """Bytes per second."""
        return self.size / self.seconds if self.seconds > 0 else 0.0


def check_destination(local: Path, *, overwrite: bool) -> Path:
    """``local`` if a download may be written there, else LocalFileError saying why (nothing touched)."""
    if local.is_dir():
        raise LocalFileError(f"{local} is a folder; give a file name")
    if (local.exists() or local.is_symlink()) and not overwrite:
        raise LocalFileError(f"{local} already exists (give --force to replace it)")
    parent = local.parent
    if not parent.is_dir():
        raise LocalFileError(f"no folder {parent} to write {local.name} into")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise LocalFileError(f"cannot write into {parent} (no permission)")
    return local


async def download_file(
    client: AriaClient,
    remote: str,
    local: Path,
    *,
    overwrite: bool = False,
    progress: Progress | None = None,
    timeout: float = REPLY_TIMEOUT,
    size: int | None = None,
) -> Transfer:
    """Fetch ``remote`` (a path on the robot) into ``local``; see the module notes.

    ``size``: the file's listed size when the caller already has it; otherwise it is listed first where
    the robot offers listings. Refused (exit 6) with the robot's words; SizeLie / MalformedReply for a
    robot that cannot be trusted; LocalFileError when ``local`` cannot be written.
    """
    remote = remote_path(remote)
    source = data_for(client, "download")
    check_destination(local, overwrite=overwrite)
    if size is None and offers(client, "list"):
        try:
            entry = await find_entry(client, remote, timeout=timeout)
        except Refused:  # ARIA lists folders by their exact name but finds files ignoring case
            entry = DirEntry(EntryKind.FILE, remote, 0, 0, MAX_DOWNLOAD - GROWTH_SLACK)
        if entry is None:
            raise Refused(f"the robot lists no file {visible(repr(remote))}")
        if entry.is_folder:
            raise Refused(f"{visible(repr(remote))} is a folder on the robot, not a file")
        size = entry.size if entry.size < MAX_DOWNLOAD - GROWTH_SLACK else None
    limit = MAX_DOWNLOAD if size is None else size + GROWTH_SLACK
    started = time.monotonic()
    fd, temp = _temp_beside(local)
    try:
        with os.fdopen(fd, "wb") as out:
            got, mtime = await _receive(client, source, remote, out, limit, size, progress, timeout)
            await asyncio.get_running_loop().run_in_executor(None, _sync, out)
        if mtime is not None:
            os.utime(temp, (mtime, mtime))
        _place(temp, local, overwrite)
    finally:
        with contextlib.suppress(FileNotFoundError):
            temp.unlink()
    return Transfer(remote, local, got, time.monotonic() - started, size, mtime)


async def _receive(
    client: AriaClient,
    source: str,
    remote: str,
    out: BinaryIO,
    limit: int,
    total: int | None,
    progress: Progress | None,
    timeout: float,
) -> tuple[int, int | None]:
    """The file's bytes into ``out`` until the robot's end of file; (bytes, modification time)."""
    stamped = source == "getFileWithTimestamp"
    request = GetFileWithTimestampRequest(remote) if stamped else GetFileRequest(remote)
    decode = TimestampedFileChunk.decode if stamped else FileChunk.decode
    loop = asyncio.get_running_loop()
    got = 0
    batch: list[bytes] = []
    batched = 0
    mtime: int | None = None
    complete = False
    shown = visible(repr(remote))
    async with closing_stream(client.stream(request, timeout=timeout, max_bytes=BACKLOG)) as packets:
        async for payload in packets:
            try:
                chunk = decode(payload)
            except ProtocolError as exc:
                raise malformed(f"file packet for {shown}", exc) from None
            if chunk.end:
                break
            if chunk.name.replace("\\", "/").lower() != remote.lower():
                raise MalformedReply(f"the robot answered {shown} with {visible(repr(chunk.name))}")
            if chunk.code != GetFileCode.OK:
                raise Refused(
                    f"the robot did not send {shown}: {code_words(GET_FILE_WORDS, chunk.code)}", chunk.code
                )
            if complete:
                raise MalformedReply(f"the robot sent more of {shown} after saying the file was complete")
            mtime = chunk.mtime
            if chunk.end_of_file:
                complete = True
                continue
            got += len(chunk.data)
            if got > limit:
                said = "any file may have" if total is None else f"the {total} it listed"
                raise SizeLie(f"the robot sent more bytes of {shown} than {said}; download stopped")
            batch.append(chunk.data)
            batched += len(chunk.data)
            if batched >= WRITE_BATCH:
                await loop.run_in_executor(None, out.write, b"".join(batch))
                batch, batched = [], 0
            if progress is not None:
                progress(got, total)
    if not complete:
        raise MalformedReply(f"the robot ended {shown} without saying the file was complete")
    if batch:
        await loop.run_in_executor(None, out.write, b"".join(batch))
    return got, mtime


def _temp_beside(local: Path) -> tuple[int, Path]:
    """A new hidden file beside ``local``, created with the permissions any new file gets (the umask)."""
    for _ in range(100):
        temp = local.parent / f".{local.name}.{secrets.token_hex(4)}.part"
        try:
            return os.open(temp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666), temp
        except FileExistsError:
            continue
    raise LocalFileError(f"cannot make a temporary file beside {local}")


def _sync(out: BinaryIO) -> None:
    out.flush()
    os.fsync(out.fileno())


def _place(temp: Path, local: Path, overwrite: bool) -> None:
    """The finished temporary file takes the destination's name; never over a file that appeared since."""
    if overwrite:
        os.replace(temp, local)
        return
    try:
        os.link(temp, local)  # fails if something took the name meanwhile: no file is ever replaced
    except FileExistsError:
        raise LocalFileError(f"{local} appeared while downloading; the download was not saved") from None
    except OSError:  # a file system without hard links
        if local.exists():
            raise LocalFileError(f"{local} appeared while downloading; the download was not saved") from None
        os.replace(temp, local)

"""Upload one file to the robot (``putFile`` and its variants), read from disk a batch at a time.

ARIA offers two ways. The plain ``putFile`` (its "fast" way, what ARIA's own client picks first) sends a
start, the data and a "done" without waiting; the robot answers only a refusal (at any point: another
client is uploading the same file, its upload stalled and was taken over, the folder is missing …) and the
final result. RTMU listens for those answers while it sends and stops at the first refusal, and paces
itself on the socket (never more than the link's buffer ahead), so memory stays flat. The interleaved
variants answer every packet (code 10), and RTMU sends the next one only then: slower on a long link,
but every refusal comes at once. The timestamp variants also keep the local file's modification time.

The robot writes into a temporary file of its own and moves it into place at the end, so a refused or
cancelled upload leaves the robot's file as it was. A cancel sends ARIA's cancel command.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import time
from collections.abc import AsyncIterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO, Final

from ..base.textsafe import visible
from ..protocol.errors import ProtocolError
from ..protocol.payloads.base import Side, payload_type
from ..protocol.payloads.files import (
    FILE_CHUNK,
    PUT_FILE_WORDS,
    PutFileCode,
    PutFileCommand,
    PutFileInterleavedRequest,
    PutFileReply,
    PutFileRequest,
    PutFileWithTimestampInterleavedRequest,
    PutFileWithTimestampRequest,
    code_words,
)
from .call_values import Packet
from .connection import REPLY_TIMEOUT, AriaClient
from .download import LocalFileError, Progress, Transfer
from .errors import ClientTimeout, NotSupported
from .remote_files import FEATURES, Refused, malformed, remote_path

READ_BATCH: Final = 35 * FILE_CHUNK
"""Bytes read from disk at once (off the network loop), then sent in ARIA's 30 000-byte packets."""
MOVE_RATE: Final = 10 << 20
"""Bytes a second a robot is given to move a finished file into place (ARIA runs ``mv`` from /tmp)."""
INTERLEAVED: Final = frozenset({"putFileInterleaved", "putFileWithTimestampInterleaved"})
REQUESTS: Final[dict[str, type[PutFileRequest]]] = {
    "putFile": PutFileRequest,
    "putFileInterleaved": PutFileInterleavedRequest,
    "putFileWithTimestamp": PutFileWithTimestampRequest,
    "putFileWithTimestampInterleaved": PutFileWithTimestampInterleavedRequest,
}


def choose_variant(client: AriaClient, *, interleaved: bool | None = None, keep_time: bool = True) -> str:
    """The ``putFile`` data to use: ARIA's order (timestamped first when asked, the fast way before the
    interleaved one unless ``interleaved`` says which); NotSupported in plain words when none fits."""
    names, reason = FEATURES["upload"]
    ranked = sorted(names, key=lambda n: ("Timestamp" not in n) if keep_time else ("Timestamp" in n))
    for name in ranked:
        if interleaved is not None and (name in INTERLEAVED) != interleaved:
            continue
        if client.supports(name):
            return name
    if interleaved is not None and any(client.supports(n) for n in names):
        way = "packet by packet (interleaved)" if interleaved else "in one stream (putFile)"
        raise NotSupported(names[0], f"this robot does not accept files {way}")
    raise NotSupported(names[0], reason + " — or this user may not use it")


@dataclass(slots=True)
class _Answers:
    """What the robot answered about our file while we sent it (plain ``putFile``)."""

    name: str
    code: int | None = None
    malformed: ProtocolError | None = None
    arrived: asyncio.Event = field(default_factory=asyncio.Event)

    def hear(self, packet: Packet) -> None:
        try:
            reply = PutFileReply.decode(packet.payload)
        except ProtocolError as exc:
            self.malformed = exc
            self.arrived.set()
            return
        if reply.name != self.name or reply.code == PutFileCode.NEXT or self.code is not None:
            return
        self.code = reply.code
        self.arrived.set()


def check_source(local: Path) -> int:
    """The size of ``local`` if it is a readable file, else LocalFileError saying why."""
    try:
        info = local.stat()
    except FileNotFoundError:
        raise LocalFileError(f"no file {local}") from None
    except OSError as exc:
        raise LocalFileError(f"cannot read {local}: {exc.strerror or exc}") from None
    if not local.is_file():
        raise LocalFileError(f"{local} is not a file")
    if not os.access(local, os.R_OK):
        raise LocalFileError(f"cannot read {local} (no permission)")
    return info.st_size


async def upload_file(
    client: AriaClient,
    local: Path,
    remote: str,
    *,
    progress: Progress | None = None,
    timeout: float = REPLY_TIMEOUT,
    interleaved: bool | None = None,
    keep_time: bool = True,
) -> Transfer:
    """Send ``local`` to ``remote`` (a path on the robot); see the module notes.

    Refused (exit 6) with the robot's words, at whatever point it refuses; LocalFileError when ``local``
    cannot be read; ClientTimeout when the robot stops reading or answering.
    """
    remote = remote_path(remote)
    size = check_source(local)
    name = choose_variant(client, interleaved=interleaved, keep_time=keep_time)
    make = REQUESTS[name]
    mtime = max(-(2**31), min(int(local.stat().st_mtime), 2**31 - 1))
    started = time.monotonic()
    with local.open("rb") as source:
        if name in INTERLEAVED:
            await _send_interleaved(client, name, make, source, remote, size, mtime, progress, timeout)
        else:
            await _send_streamed(client, name, make, source, remote, size, mtime, progress, timeout)
    return Transfer(remote, local, size, time.monotonic() - started, size)


async def _chunks(source: BinaryIO) -> AsyncIterator[bytes]:
    """The file in ARIA's 30 000-byte pieces, read a batch at a time off the loop; at least one piece."""
    loop = asyncio.get_running_loop()
    sent_any = False
    while True:
        batch = await loop.run_in_executor(None, source.read, READ_BATCH)
        if not batch:
            break
        for start in range(0, len(batch), FILE_CHUNK):
            sent_any = True
            yield batch[start : start + FILE_CHUNK]
    if not sent_any:
        yield b""  # ARIA always sends a last (here empty) data packet before "done"


def _refusal(remote: str, code: int) -> Refused:
    return Refused(f"the robot refused {visible(repr(remote))}: {code_words(PUT_FILE_WORDS, code)}", code)


async def _send_streamed(
    client: AriaClient,
    name: str,
    make: type[PutFileRequest],
    source: BinaryIO,
    remote: str,
    size: int,
    mtime: int,
    progress: Progress | None,
    timeout: float,
) -> None:
    answers = _Answers(remote)
    client.listen(name, answers.hear)
    finished = False
    try:
        client.send(make(PutFileCommand.START, remote, mtime=mtime))
        sent = 0
        async for data in _chunks(source):
            _check(answers, remote)
            client.send(make(PutFileCommand.DATA, remote, data))
            await client.drain(timeout)
            sent += len(data)
            if progress is not None:
                progress(sent, size)
        _check(answers, remote)
        client.send(make(PutFileCommand.DONE, remote))
        try:
            async with asyncio.timeout(timeout + size / MOVE_RATE):
                await answers.arrived.wait()
        except TimeoutError:
            raise ClientTimeout(f"the robot did not confirm {visible(repr(remote))} in time") from None
        _check(answers, remote)
        finished = True
    finally:
        if not finished:
            _cancel(client, make, remote)
        with contextlib.suppress(Exception):
            client.listen(name, None)


def _check(answers: _Answers, remote: str) -> None:
    if answers.malformed:
        raise malformed(f"answer about {visible(repr(remote))}", answers.malformed)
    if answers.code is not None and answers.code != PutFileCode.DONE:
        raise _refusal(remote, answers.code)


async def _send_interleaved(
    client: AriaClient,
    name: str,
    make: type[PutFileRequest],
    source: BinaryIO,
    remote: str,
    size: int,
    mtime: int,
    progress: Progress | None,
    timeout: float,
) -> None:
    reply_type = payload_type(name, Side.REPLY)
    assert reply_type is not None and issubclass(reply_type, PutFileReply)
    finished = False

    async def ask(request: PutFileRequest, wanted: int, wait: float) -> None:
        reply = await client.request_once(request, timeout=wait)
        try:
            answer = reply_type.decode(reply.payload)
        except ProtocolError as exc:
            raise malformed(f"answer about {visible(repr(remote))}", exc) from None
        if answer.code != wanted:
            raise _refusal(remote, answer.code)

    try:
        await ask(make(PutFileCommand.START, remote, mtime=mtime), PutFileCode.NEXT, timeout)
        sent = 0
        async for data in _chunks(source):
            await ask(make(PutFileCommand.DATA, remote, data), PutFileCode.NEXT, timeout)
            sent += len(data)
            if progress is not None:
                progress(sent, size)
        await ask(make(PutFileCommand.DONE, remote), PutFileCode.DONE, timeout + size / MOVE_RATE)
        finished = True
    finally:
        if not finished:
            _cancel(client, make, remote)


def _cancel(client: AriaClient, make: type[PutFileRequest], remote: str) -> None:
    """Best effort: tell the robot to drop its temporary file (the link may be gone already)."""
    with contextlib.suppress(Exception):
        if client.connected:
            client.send(make(PutFileCommand.CANCEL, remote))

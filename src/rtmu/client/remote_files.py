"""Files on the robot (ARIA's ``ArServerFileUtils``): which services a server offers, its folders, deleting.

Every name a server sends is untrusted: a listing whose entry is not one plain name (``..``, a slash, a
control character, a name ARIA would never list) is refused whole with the entry named, so nothing a
caller builds from it can leave the folder the operator chose; a listing longer than
:data:`MAX_ENTRIES` is refused as soon as it passes that. The names RTMU sends are checked too
(:func:`remote_path`), so a mistake is said in plain words before the robot is asked.

Each service is a feature a window greys with the reason when the server does not list its data
(:func:`unavailable`); calling one anyway raises :class:`NotSupported` with the same words. Downloads and
uploads are in :mod:`.download` and :mod:`.upload`.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import AsyncGenerator, AsyncIterator
from dataclasses import dataclass
from typing import Final, cast

from ..base.exit_codes import EXIT_REFUSED
from ..base.i18n import N_, Said
from ..base.textsafe import visible
from ..protocol.errors import ProtocolError
from ..protocol.payloads.files import (
    DELETE_FILE_WORDS,
    LISTING_WORDS,
    MAX_NAME,
    DefaultUploadDownloadDir,
    DeleteFileCode,
    DeleteFileReply,
    DeleteFileRequest,
    DirEntry,
    DirListing,
    DirListingMultipleRequest,
    DirListingPacket,
    DirListingRequest,
    EntryKind,
    ListingCode,
    code_words,
)
from .connection import REPLY_TIMEOUT, AriaClient
from .errors import ClientError, MalformedReply, NotSupported

MAX_ENTRIES: Final = 20_000
"""A folder listing longer than this is refused (a hostile server could list entries for ever)."""
MAX_ENTRY_NAME: Final = 255
"""Longer than any file name a robot's file system can hold."""
LISTING_BACKLOG: Final = 4 << 20
"""Bytes of listing packets that may wait unread (each is at most 32 kB)."""

FEATURES: Final[dict[str, tuple[tuple[str, ...], str]]] = {
    "list": (
        ("getDirListingMultiplePackets", "getDirListing"),
        "this robot does not let its files be listed (it offers no getDirListing)",
    ),
    "download": (
        ("getFileWithTimestamp", "getFile"),
        "this robot does not let its files be downloaded (it offers no getFile)",
    ),
    "upload": (
        ("putFileWithTimestamp", "putFile", "putFileWithTimestampInterleaved", "putFileInterleaved"),
        "this robot does not accept files (it offers no putFile)",
    ),
    "delete": (("deleteFile",), "this robot does not let its files be deleted (it offers no deleteFile)"),
    "default_folder": (
        ("getDefaultUploadDownloadDir",),
        "this robot names no default folder for transfers (it offers no getDefaultUploadDownloadDir)",
    ),
}
"""Feature → (the data that serve it, best first; why it is unavailable when none is listed)."""
_FOR_USER: Final = " — or this user may not use it"


class Refused(ClientError):
    """The robot answered, and said no (no such file, outside its folder, busy …): its words, exit 6."""

    exit_code = EXIT_REFUSED
    kind = "refused"

    def __init__(self, message: str, code: int | None = None) -> None:
        super().__init__(message)
        self.code = code


class UnsafeName(MalformedReply):
    """The robot sent a name that is not one plain file name: nothing is built from it."""


class ListingTooLarge(MalformedReply):
    """More entries than :data:`MAX_ENTRIES`: the listing is dropped rather than kept growing."""


def closing_stream(stream: AsyncIterator[bytes]) -> contextlib.aclosing[AsyncGenerator[bytes, None]]:
    """``client.stream(...)`` closed on leaving the block, so an early exit gives its reply up at once."""
    return contextlib.aclosing(cast(AsyncGenerator[bytes, None], stream))


def malformed(what: str, exc: ProtocolError) -> MalformedReply:
    """One line for a packet that does not decode: "the robot's <what> is malformed: why"."""
    return MalformedReply(f"the robot's {what} is malformed: {exc}")


def offers(client: AriaClient, feature: str) -> bool:
    """Whether this server lists any data that serves ``feature`` (to this user)."""
    return any(client.supports(name) for name in FEATURES[feature][0])


def unavailable(client: AriaClient) -> dict[str, str]:
    """Feature → why it cannot be used with this server, for every feature it lacks (greyed in a window)."""
    missing = (f for f in FEATURES if not offers(client, f))
    return {feature: FEATURES[feature][1] + _FOR_USER for feature in missing}


def data_for(client: AriaClient, feature: str) -> str:
    """The best data this server lists for ``feature``; NotSupported (plain words) when none."""
    names, reason = FEATURES[feature]
    for name in names:
        if client.supports(name):
            return name
    raise NotSupported(names[0], reason + _FOR_USER)


def name_problem(name: str) -> str:
    """Why ``name`` cannot be one plain file name that a robot lists ("" when it can be): English, marked
    (``as_said`` says it in the operator's language)."""
    if not name:
        return N_("it is empty")
    if name in (".", ".."):
        return N_("it names a folder above or the folder itself")
    if "/" in name or "\\" in name:
        return N_("it holds a slash")
    if visible(name) != name:
        return N_("it holds a control character")
    if name.startswith("."):
        return N_("it starts with a dot (ARIA lists no such names)")
    if len(name) > MAX_ENTRY_NAME:
        return Said(N_("it is longer than {count} characters"), count=MAX_ENTRY_NAME)
    return ""


def checked_name(name: str, what: str) -> str:
    """``name`` if it is one plain file name, else :class:`UnsafeName` saying which and why."""
    problem = name_problem(name)
    if problem:
        raise UnsafeName(
            f"the robot sent {what} {visible(repr(name))}, which is not a plain file name: {problem}"
        )
    return name


def remote_path(path: str, *, folder: bool = False) -> str:
    """A path on the robot as RTMU will send it (``a/b/c``), or ValueError saying what is wrong.

    Relative to the robot's shared folder; each part one plain name; ``""`` (the shared folder itself)
    only where ``folder`` allows it.
    """
    parts = [p for p in path.replace("\\", "/").split("/") if p]
    if path.startswith(("/", "~", "\\")):
        raise ValueError(
            f"{visible(path)!r}: give a path inside the robot's folder, without a leading / or ~"
        )
    if not parts and not folder:
        raise ValueError("no file name given")
    for part in parts:
        if part in (".", ".."):
            raise ValueError(f"{visible(path)!r}: '.' and '..' cannot be used (ARIA refuses them)")
        if visible(part) != part:
            raise ValueError(f"{visible(path)!r}: a control character cannot be part of a file name")
    joined = "/".join(parts)
    if len(joined) > MAX_NAME:
        raise ValueError(f"the path is longer than the {MAX_NAME} characters ARIA reads")
    return joined


def local_name(name: str) -> str:
    """A checked name from the robot as this computer's file system spells it (the same bytes)."""
    return os.fsdecode(checked_name(name, "a file named").encode("latin-1"))


def wire_name(name: str) -> str:
    """A local file name as the robot will see it: its bytes, which ARIA strings carry as they are."""
    return os.fsencode(name).decode("latin-1")


def split_path(path: str) -> tuple[str, str]:
    """(folder, name) of a checked remote path."""
    folder, _, name = path.rpartition("/")
    return folder, name


@dataclass(frozen=True, slots=True)
class Listing:
    """One folder on the robot: its entries as listed (each name checked), folders first if sorted."""

    folder: str
    entries: tuple[DirEntry, ...]
    source: str
    """The data it came from (``getDirListingMultiplePackets`` or ``getDirListing``)."""
    skipped: int = 0
    """Entries of a kind ARIA does not define (neither folder nor file): left out, as ARIA's clients do."""

    def find(self, name: str) -> DirEntry | None:
        """The entry named ``name``: exactly, else ignoring case (as ARIA matches names)."""
        exact = next((e for e in self.entries if e.name == name), None)
        if exact is not None:
            return exact
        lowered = name.lower()
        return next((e for e in self.entries if e.name.lower() == lowered), None)

    def sorted(self) -> tuple[DirEntry, ...]:
        """Folders, then files, each without regard to case (how ARIA's one-packet listing orders them)."""
        return tuple(sorted(self.entries, key=lambda e: (not e.is_folder, e.name.lower(), e.name)))


async def list_folder(
    client: AriaClient, folder: str = "", *, timeout: float = REPLY_TIMEOUT, max_entries: int = MAX_ENTRIES
) -> Listing:
    """List ``folder`` (relative to the robot's shared folder; ``""`` is that folder itself).

    Refused (exit 6) with the robot's words for a folder it will not list; UnsafeName / ListingTooLarge
    for a listing that cannot be trusted; NotSupported where the robot lists nothing.
    """
    folder = remote_path(folder, folder=True)
    source = data_for(client, "list")
    if source == "getDirListing":
        reply = await client.request_once(DirListingRequest(folder), timeout=timeout)
        try:
            single = DirListing.decode(reply.payload)
        except ProtocolError as exc:
            raise MalformedReply(
                f"the robot's listing of {visible(repr(folder))} is malformed: {exc}"
            ) from None
        _check_answer(single.code, single.folder, folder)
        return _listing(folder, single.entries, source, 0, max_entries)
    entries: list[DirEntry] = []
    skipped = 0
    stream = client.stream(DirListingMultipleRequest(folder), timeout=timeout, max_bytes=LISTING_BACKLOG)
    async with closing_stream(stream) as packets:
        async for payload in packets:
            try:
                packet = DirListingPacket.decode(payload)
            except ProtocolError as exc:
                raise MalformedReply(
                    f"the robot's listing of {visible(repr(folder))} is malformed: {exc}"
                ) from None
            if packet.end:
                break
            _check_answer(packet.code, packet.folder, folder)
            for entry in packet.entries:
                if entry.kind not in (EntryKind.FOLDER, EntryKind.FILE):
                    skipped += 1
                    continue
                entries.append(entry)
            if len(entries) > max_entries:
                raise ListingTooLarge(
                    f"the robot listed more than {max_entries} entries in {visible(repr(folder or '/'))}; "
                    "the listing was stopped"
                )
    return _listing(folder, tuple(entries), source, skipped, max_entries)


def _check_answer(code: int, answered: str, asked: str) -> None:
    if code != ListingCode.OK:
        where = visible(repr(asked or "/"))
        raise Refused(f"the robot will not list {where}: {code_words(LISTING_WORDS, code)}", code)
    if answered != asked:
        raise MalformedReply(
            f"the robot answered a listing of {visible(repr(asked))} with one of {visible(repr(answered))}"
        )


def _listing(folder: str, entries: tuple[DirEntry, ...], source: str, skipped: int, limit: int) -> Listing:
    if len(entries) > limit:
        raise ListingTooLarge(f"the robot listed more than {limit} entries in {visible(repr(folder or '/'))}")
    for entry in entries:
        checked_name(entry.name, f"an entry of {visible(repr(folder or '/'))} named")
    return Listing(folder, entries, source, skipped)


async def find_entry(client: AriaClient, path: str, *, timeout: float = REPLY_TIMEOUT) -> DirEntry | None:
    """The listed entry for ``path`` (None when its folder does not list it); needs listing."""
    folder, name = split_path(remote_path(path))
    return (await list_folder(client, folder, timeout=timeout)).find(name)


async def delete_file(client: AriaClient, path: str, *, timeout: float = REPLY_TIMEOUT) -> None:
    """Delete one file on the robot; Refused with its words when it will not."""
    path = remote_path(path)
    data_for(client, "delete")
    reply = await client.request_once(DeleteFileRequest(path), timeout=timeout)
    try:
        answer = DeleteFileReply.decode(reply.payload)
    except ProtocolError as exc:
        raise MalformedReply(
            f"the robot's answer to deleting {visible(repr(path))} is malformed: {exc}"
        ) from None
    if answer.code != DeleteFileCode.DELETED:
        words = code_words(DELETE_FILE_WORDS, answer.code)
        raise Refused(f"the robot did not delete {visible(repr(path))}: {words}", answer.code)


async def default_folder(client: AriaClient, *, timeout: float = REPLY_TIMEOUT) -> str:
    """The folder the robot suggests for transfers (checked: a relative path inside its folder)."""
    data_for(client, "default_folder")
    reply = await client.request_once(DefaultUploadDownloadDir.DATA_NAME, timeout=timeout)
    try:
        folder = DefaultUploadDownloadDir.decode(reply.payload).folder
    except ProtocolError as exc:
        raise malformed("default folder", exc) from None
    try:
        return remote_path(folder, folder=True)
    except ValueError as exc:
        raise UnsafeName(f"the robot's default folder cannot be used: {exc}") from None

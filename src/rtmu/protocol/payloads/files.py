"""ARIA's file services (``ArServerFileUtils``): list, get, put and delete files in a shared folder.

Every name is relative to the folder the server was started with; a server answers with a return code
and the name as it was asked, so a client can pair answers with its requests.

* ``getDirListing``: one packet (folders, then files, each sorted without regard to case);
  ``getDirListingMultiplePackets``: entries in the order the folder gives them, spread over packets of
  at most 32 000 bytes, then one empty packet. An error is one packet with the code and the folder.
* ``getFile`` / ``getFileWithTimestamp``: the file in packets of at most :data:`FILE_CHUNK` bytes, then a
  packet with 0 bytes (the end of the file), then one empty packet (the end of the reply). The timestamp
  variant puts the file's modification time after each byte count. A file sent this way carries no size:
  a client learns it from the listing.
* ``putFile`` and its three variants: the client sends a start, the data packets and a "done"; the plain
  variants answer only errors and the final result, the interleaved ones answer every packet (code 10)
  so the client sends the next one only then.
* ``deleteFile``: one answer. ``getDefaultUploadDownloadDir``: a folder name, listed only where the
  server was given one.

Sizes and counts come from the server and are checked before anything is allocated (a byte count that
does not fit the packet is refused).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from enum import IntEnum
from typing import ClassVar, Final, Self

from ..errors import PayloadError
from ..fields import FieldReader, FieldWriter
from .base import Payload, Side, SingleField, checked_count, register

FILE_CHUNK: Final = 30_000
"""The most file bytes ARIA puts in one ``getFile`` or ``putFile`` packet."""
MAX_NAME: Final = 2047
"""ARIA reads every file and folder name into a 2048-byte buffer."""
ENTRY_MIN_BYTES: Final = 13
"""The smallest ``getDirListing`` entry: an empty name's NUL and three ``ubyte4``."""


class EntryKind(IntEnum):
    """What ``getDirListingMultiplePackets`` says an entry is (ARIA's clients ignore other values)."""

    FOLDER = 1
    FILE = 2


@dataclass(frozen=True, slots=True)
class DirEntry:
    """One listed folder or file: times are Unix seconds, ``size`` in bytes (both ``ubyte4`` on the wire)."""

    kind: int
    """:class:`EntryKind` value; anything else is kept as sent."""
    name: str
    atime: int
    mtime: int
    size: int

    @property
    def is_folder(self) -> bool:
        return self.kind == EntryKind.FOLDER

    @property
    def is_file(self) -> bool:
        return self.kind == EntryKind.FILE


def _u32(value: int) -> int:
    """A time or size as ARIA's ``ubyte4`` carries it (a file over 4 GiB wraps)."""
    return value & 0xFFFF_FFFF


def _read_entry(r: FieldReader, kind: int) -> DirEntry:
    name = r.string("entry name")
    return DirEntry(kind, name, r.ubyte4("access time"), r.ubyte4("modification time"), r.ubyte4("size"))


def _write_entry(w: FieldWriter, e: DirEntry) -> None:
    w.string(e.name).ubyte4(_u32(e.atime)).ubyte4(_u32(e.mtime)).ubyte4(_u32(e.size))


class ListingCode(IntEnum):
    OK = 0
    OUTSIDE = 1
    """The folder asked for starts with ``/``, ``~`` or ``\\``, or holds ``..``."""
    NO_FOLDER = 2
    """No such folder, or it cannot be read."""


LISTING_WORDS: Final[Mapping[int, str]] = {
    ListingCode.OUTSIDE: "that folder is outside the folder the robot shares",
    ListingCode.NO_FOLDER: "no such folder on the robot (or it cannot be read)",
}


@register
@dataclass(frozen=True, slots=True)
class DirListingRequest(SingleField):
    """``getDirListing`` args: the folder, relative to the shared one (``""`` is the shared folder itself)."""

    DATA_NAME = "getDirListing"
    SIDE = Side.ARGS
    FIELD_KIND = "string"
    FIELD_LABEL = "folder"

    folder: str


@register
@dataclass(frozen=True, slots=True)
class DirListingMultipleRequest(DirListingRequest):
    """``getDirListingMultiplePackets`` args: as ``getDirListing``."""

    DATA_NAME = "getDirListingMultiplePackets"


@register
@dataclass(frozen=True, slots=True)
class DirListing(Payload):
    """``getDirListing`` reply: ``ubyte2`` code, folder; if 0: ``ubyte2`` n folders and their entries,
    ``ubyte2`` n files and theirs (name, ``ubyte4`` access time, modification time, size)."""

    DATA_NAME = "getDirListing"
    SIDE = Side.REPLY

    code: int
    folder: str
    entries: tuple[DirEntry, ...] = ()
    """Folders first, then files (the order the packet carries them in)."""

    def encode(self) -> bytes:
        w = FieldWriter().ubyte2(self.code).string(self.folder)
        if self.code != ListingCode.OK:
            return w.bytes()
        for kind in (EntryKind.FOLDER, EntryKind.FILE):
            group = [e for e in self.entries if (e.kind == EntryKind.FOLDER) == (kind == EntryKind.FOLDER)]
            w.ubyte2(len(group))
            for e in group:
                _write_entry(w, e)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        code = r.ubyte2("return code")
        folder = r.string("folder")
        if code != ListingCode.OK:
            return cls(code, folder)
        entries: list[DirEntry] = []
        for kind, label in ((EntryKind.FOLDER, "folder count"), (EntryKind.FILE, "file count")):
            count = checked_count(r.ubyte2(label), ENTRY_MIN_BYTES, r, label)
            entries += [_read_entry(r, kind) for _ in range(count)]
        return cls(code, folder, tuple(entries))


@register
@dataclass(frozen=True, slots=True)
class DirListingPacket(Payload):
    """One ``getDirListingMultiplePackets`` packet: ``ubyte2`` code, folder; if 0: ``ubyte2`` n, then n
    entries each led by a ``byte`` kind (1 folder, 2 file). An empty packet (``end``) ends the reply."""

    DATA_NAME = "getDirListingMultiplePackets"
    SIDE = Side.REPLY

    code: int = 0
    folder: str = ""
    entries: tuple[DirEntry, ...] = ()
    end: bool = False

    def encode(self) -> bytes:
        if self.end:
            return b""
        w = FieldWriter().ubyte2(self.code).string(self.folder)
        if self.code != ListingCode.OK:
            return w.bytes()
        w.ubyte2(len(self.entries))
        for e in self.entries:
            w.ubyte(e.kind)
            _write_entry(w, e)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        if not data:
            return cls(end=True)
        r = FieldReader(data)
        code = r.ubyte2("return code")
        folder = r.string("folder")
        if code != ListingCode.OK:
            return cls(code, folder)
        count = checked_count(r.ubyte2("entry count"), ENTRY_MIN_BYTES + 1, r, "entry count")
        return cls(code, folder, tuple(_read_entry(r, r.ubyte("entry kind")) for _ in range(count)))


# -- getFile ---------------------------------------------------------------------------------------------


class GetFileCode(IntEnum):
    OK = 0
    OUTSIDE = 1
    NO_FILE = 2
    EMPTY_NAME = 3
    READ_ERROR = 4
    """Reading failed on the robot (it can come after good packets)."""


GET_FILE_WORDS: Final[Mapping[int, str]] = {
    GetFileCode.OUTSIDE: "that file is outside the folder the robot shares",
    GetFileCode.NO_FILE: "no such file on the robot (or it cannot be read)",
    GetFileCode.EMPTY_NAME: "no file name was given",
    GetFileCode.READ_ERROR: "the robot could not read the file (is it a folder?)",
}


@register
@dataclass(frozen=True, slots=True)
class GetFileRequest(Payload):
    """``getFile`` args: the file's name, then ``ubyte2`` operation (0: get; ARIA reads no further)."""

    DATA_NAME = "getFile"
    SIDE = Side.ARGS

    name: str
    operation: int = 0

    def encode(self) -> bytes:
        return FieldWriter().string(self.name).ubyte2(self.operation).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(r.string("file name"), r.ubyte2("operation", default=0))


@register
@dataclass(frozen=True, slots=True)
class GetFileWithTimestampRequest(GetFileRequest):
    """``getFileWithTimestamp`` args: as ``getFile``."""

    DATA_NAME = "getFileWithTimestamp"


@register
@dataclass(frozen=True, slots=True)
class FileChunk(Payload):
    """One ``getFile`` packet: ``ubyte2`` code, name; if 0: ``ubyte4`` n and n bytes of the file.

    n = 0 is the end of the file; an empty packet (``end``) then ends the reply. A count that does
    not fit the packet is refused before anything is read.
    """

    DATA_NAME = "getFile"
    SIDE = Side.REPLY
    TIMESTAMPED: ClassVar[bool] = False

    code: int = 0
    name: str = ""
    data: bytes = b""
    mtime: int | None = None
    """``getFileWithTimestamp`` only: the file's modification time (Unix seconds, ``byte4``)."""
    end: bool = False

    @property
    def end_of_file(self) -> bool:
        """The packet with no bytes that says the whole file was sent."""
        return not self.end and self.code == GetFileCode.OK and not self.data

    def encode(self) -> bytes:
        if self.end:
            return b""
        w = FieldWriter().ubyte2(self.code).string(self.name)
        if self.code != GetFileCode.OK:
            return w.bytes()
        w.ubyte4(len(self.data))
        if self.TIMESTAMPED:
            w.byte4(self.mtime or 0)
        return w.raw(self.data).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        if not data:
            return cls(end=True)
        r = FieldReader(data)
        code = r.ubyte2("return code")
        name = r.string("file name")
        if code != GetFileCode.OK:
            return cls(code, name)
        count = r.ubyte4("byte count")
        mtime = r.byte4("modification time") if cls.TIMESTAMPED else None
        if count > r.remaining:
            raise PayloadError(f"a file packet claims {count} bytes but carries {r.remaining}")
        return cls(code, name, r.raw(count, "file bytes"), mtime)


@register
@dataclass(frozen=True, slots=True)
class TimestampedFileChunk(FileChunk):
    """One ``getFileWithTimestamp`` packet: as ``getFile``, with ``byte4`` modification time after n."""

    DATA_NAME = "getFileWithTimestamp"
    TIMESTAMPED = True


# -- putFile -------------------------------------------------------------------------------------------


class PutFileCommand(IntEnum):
    START = 0
    DATA = 1
    DONE = 2
    CANCEL = 3


class PutFileCode(IntEnum):
    DONE = 0
    GETTING = 1
    OUTSIDE = 2
    BAD_FOLDER = 3
    BAD_NAME = 4
    CANNOT_WRITE = 5
    CANNOT_MOVE = 6
    BUSY = 7
    TAKEN_OVER = 8
    UNKNOWN_PUT = 9
    NEXT = 10
    """Interleaved variants: packet taken, send the next."""
    CANCELLED = 11


PUT_FILE_WORDS: Final[Mapping[int, str]] = {
    PutFileCode.OUTSIDE: "that place is outside the folder the robot shares",
    PutFileCode.BAD_FOLDER: "no such folder on the robot",
    PutFileCode.BAD_NAME: "the robot cannot use that file name",
    PutFileCode.CANNOT_WRITE: "the robot could not write its temporary file (disk full or no permission?)",
    PutFileCode.CANNOT_MOVE: "the robot could not move the file into place (no permission?)",
    PutFileCode.BUSY: "another client is uploading that file right now",
    PutFileCode.TAKEN_OVER: "the upload stalled for 15 s and another client took the file over",
    PutFileCode.UNKNOWN_PUT: "the robot has no upload of that file under way (it was refused or taken over)",
    PutFileCode.CANCELLED: "the upload was cancelled",
}


@register
@dataclass(frozen=True, slots=True)
class PutFileRequest(Payload):
    """``putFile`` args: ``ubyte2`` command, the file's name; a data packet adds ``ubyte4`` n and n bytes.

    The timestamp variants add ``byte4`` modification time to the start packet.
    """

    DATA_NAME = "putFile"
    SIDE = Side.ARGS
    TIMESTAMPED: ClassVar[bool] = False

    command: int
    name: str
    data: bytes = b""
    mtime: int | None = None

    def encode(self) -> bytes:
        w = FieldWriter().ubyte2(self.command).string(self.name)
        if self.command == PutFileCommand.START and self.TIMESTAMPED:
            w.byte4(self.mtime or 0)
        elif self.command == PutFileCommand.DATA:
            w.ubyte4(len(self.data)).raw(self.data)
        return w.bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        command = r.ubyte2("command")
        name = r.string("file name")
        if command == PutFileCommand.START and cls.TIMESTAMPED:
            return cls(command, name, mtime=r.byte4("modification time"))
        if command == PutFileCommand.DATA:
            count = r.ubyte4("byte count")
            if count > r.remaining:
                raise PayloadError(f"a file packet claims {count} bytes but carries {r.remaining}")
            return cls(command, name, r.raw(count, "file bytes"))
        return cls(command, name)


@register
@dataclass(frozen=True, slots=True)
class PutFileInterleavedRequest(PutFileRequest):
    DATA_NAME = "putFileInterleaved"


@register
@dataclass(frozen=True, slots=True)
class PutFileWithTimestampRequest(PutFileRequest):
    DATA_NAME = "putFileWithTimestamp"
    TIMESTAMPED = True


@register
@dataclass(frozen=True, slots=True)
class PutFileWithTimestampInterleavedRequest(PutFileRequest):
    DATA_NAME = "putFileWithTimestampInterleaved"
    TIMESTAMPED = True


@register
@dataclass(frozen=True, slots=True)
class PutFileReply(Payload):
    """Every ``putFile*`` answer: ``ubyte2`` code (:class:`PutFileCode`), then the file's name as asked."""

    DATA_NAME = "putFile"
    SIDE = Side.REPLY

    code: int
    name: str

    def encode(self) -> bytes:
        return FieldWriter().ubyte2(self.code).string(self.name).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(r.ubyte2("return code"), r.string("file name"))


@register
@dataclass(frozen=True, slots=True)
class PutFileInterleavedReply(PutFileReply):
    DATA_NAME = "putFileInterleaved"


@register
@dataclass(frozen=True, slots=True)
class PutFileWithTimestampReply(PutFileReply):
    DATA_NAME = "putFileWithTimestamp"


@register
@dataclass(frozen=True, slots=True)
class PutFileWithTimestampInterleavedReply(PutFileReply):
    DATA_NAME = "putFileWithTimestampInterleaved"


# -- deleteFile, getDefaultUploadDownloadDir ---------------------------------------------------------------


class DeleteFileCode(IntEnum):
    DELETED = 0
    OUTSIDE = 1
    NO_FILE = 2
    EMPTY_NAME = 3


DELETE_FILE_WORDS: Final[Mapping[int, str]] = {
    DeleteFileCode.OUTSIDE: "that file is outside the folder the robot shares",
    DeleteFileCode.NO_FILE: "no such file on the robot, or it cannot be deleted (a folder? no permission?)",
    DeleteFileCode.EMPTY_NAME: "no file name was given",
}


@register
@dataclass(frozen=True, slots=True)
class DeleteFileRequest(SingleField):
    """``deleteFile`` args: the file's name."""

    DATA_NAME = "deleteFile"
    SIDE = Side.ARGS
    FIELD_KIND = "string"
    FIELD_LABEL = "file name"

    name: str


@register
@dataclass(frozen=True, slots=True)
class DeleteFileReply(PutFileReply):
    """``deleteFile`` reply: ``ubyte2`` code (:class:`DeleteFileCode`), the name as asked."""

    DATA_NAME = "deleteFile"


@register
@dataclass(frozen=True, slots=True)
class DefaultUploadDownloadDir(SingleField):
    """``getDefaultUploadDownloadDir`` reply: the folder a client should offer first for transfers."""

    DATA_NAME = "getDefaultUploadDownloadDir"
    SIDE = Side.REPLY
    FIELD_KIND = "string"
    FIELD_LABEL = "folder"

    folder: str


def code_words(words: Mapping[int, str], code: int) -> str:
    """What a return code means in plain words (a code the server invented is named as such)."""
    return words.get(code) or f"the robot answered with code {code}, which ARIA does not define"

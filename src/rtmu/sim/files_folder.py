"""The simulator's files folder, read the way ARIA's ``ArServerFileUtils`` reads its folder.

ARIA finds a file by walking from the shared folder one name at a time, comparing names without regard
to (ASCII) case and skipping every entry that starts with a dot, so ``..`` can never be walked; a leading
slash leaves an empty first name that matches nothing. Listings skip dot entries too; the one-packet
listing sorts folders and files without regard to case, the multi-packet one keeps the folder's order.
The simulator adds one guard of its own: an entry that resolves outside the folder (a symbolic link) is
treated as missing, and so is anything a name could reach only through one.
"""

from __future__ import annotations

import os
import stat
import tempfile
import weakref
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, BinaryIO, Final

from rtmu.protocol.payloads.files import DirEntry, EntryKind

if TYPE_CHECKING:
    from .context import SimHost

_ASCII_LOWER: Final = str.maketrans("ABCDEFGHIJKLMNOPQRSTUVWXYZ", "abcdefghijklmnopqrstuvwxyz")
NAME_LIMIT: Final = 2047
"""ARIA reads names into 2048-byte buffers: longer ones are cut."""


def fold(name: str) -> str:
    """A name as ARIA's ``strcasecmp`` compares it (ASCII letters only)."""
    return name.translate(_ASCII_LOWER)


def wire(name: str) -> str:
    """A name from the file system as ARIA puts it on the wire: its bytes, which RTMU reads as latin-1."""
    return os.fsencode(name).decode("latin-1")


def disk(name: str) -> str:
    """A name from the wire as the file system spells it (the same bytes)."""
    return os.fsdecode(name.encode("latin-1", "replace"))


def split_name(raw: str) -> list[str]:
    """ARIA's ``splitFileName``: parts between slashes, repeats dropped — but a leading slash (or an empty
    name) leaves one empty first part, which no entry matches."""
    text = raw.replace("\\", "/")
    parts = [p for p in text.split("/") if p]
    return ["", *parts] if text.startswith("/") or not text else parts


@dataclass
class Upload:
    """One ``putFile`` under way: where it goes, its temporary file, who sends it."""

    final: Path
    temp: Path
    file: BinaryIO
    client: int
    last_activity: float
    mtime: int | None = None


@dataclass
class FilesFolder:
    """A simulator's shared folder and the transfers under way in it."""

    root: Path
    temporary: tempfile.TemporaryDirectory[str] | None = None
    """Set when the folder is the simulator's own (removed when the simulator goes, or at exit)."""
    uploads: dict[str, Upload] = field(default_factory=dict)
    """By the name as the client sent it (ARIA's key)."""
    next_temp: int = 0

    def match(self, raw: str) -> Path | None:
        """The entry ``raw`` names, matched part by part as ARIA does; None when it names nothing."""
        parts = split_name(raw[:NAME_LIMIT])
        if parts[:1] == ["."]:
            parts = parts[1:]
        if not parts:
            return None
        here = self.root
        for part in parts:
            try:
                names = sorted(os.listdir(here))
            except OSError:
                return None
            wanted = fold(part)
            found = self.find(names, wanted)
            if found is None:
                return None
            here = here / found
        return here if self.inside(here) else None

    @staticmethod
    def find(names: list[str], wanted: str) -> str | None:
        """The first of ``names`` (file system spelling) that is ``wanted`` (folded wire spelling)."""
        return next((n for n in names if not n.startswith(".") and fold(wire(n)) == wanted), None)

    def inside(self, path: Path) -> bool:
        try:
            path.resolve().relative_to(self.root.resolve())
        except (OSError, ValueError):
            return False
        return True

    def relative(self, path: Path) -> str:
        """``path`` inside the folder as the wire spells it."""
        return wire(path.relative_to(self.root).as_posix())

    def entries(self, folder: Path) -> list[DirEntry]:
        """A folder's entries in the order the file system gives them (dot entries left out)."""
        out: list[DirEntry] = []
        with os.scandir(folder) as it:
            for entry in it:
                if entry.name.startswith("."):
                    continue
                try:
                    info = entry.stat()
                except OSError:
                    continue
                if stat.S_ISDIR(info.st_mode) and self.inside(Path(entry.path)):
                    kind = EntryKind.FOLDER
                elif stat.S_ISREG(info.st_mode) and self.inside(Path(entry.path)):
                    kind = EntryKind.FILE
                else:
                    continue
                name = wire(entry.name)
                out.append(DirEntry(kind, name, int(info.st_atime), int(info.st_mtime), info.st_size))
        return out

    def temp_file(self) -> Path:
        """A fresh hidden name in the folder for an upload's bytes (never listed, never matched)."""
        self.next_temp += 1
        return self.root / f".rtmu-sim-put.{os.getpid()}.{self.next_temp}"


_FOLDERS: weakref.WeakKeyDictionary[SimHost, FilesFolder] = weakref.WeakKeyDictionary()


def files_folder(server: SimHost) -> FilesFolder:
    """This simulator's files folder: ``--files DIR``, else a temporary one of its own."""
    folder = _FOLDERS.get(server)
    if folder is None:
        configured = server.config.files_dir
        if configured is not None:
            folder = FilesFolder(Path(configured))
        else:
            temporary = tempfile.TemporaryDirectory(prefix="rtmu-sim-files-")
            folder = FilesFolder(Path(temporary.name), temporary)
        weakref.finalize(server, _drop_uploads, folder.uploads)
        _FOLDERS[server] = folder
    return folder


def _drop_uploads(uploads: dict[str, Upload]) -> None:
    """Temporary files of uploads never finished, when the simulator goes (ARIA leaves them in /tmp)."""
    for upload in uploads.values():
        try:
            upload.file.close()
            upload.temp.unlink(missing_ok=True)
        except OSError:
            pass
    uploads.clear()

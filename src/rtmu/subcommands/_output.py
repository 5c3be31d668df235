"""Files the operator names on the command line: checked before connecting, never lost, written whole.

Every ``--out`` (``record``, ``map``, ``image``, ``video``) is checked before anything connects: a
directory where a file is wanted, a folder that does not exist or cannot be written, or a file that
exists already fail at once with one plain line (exit 2) — not after a download, and never by
deleting what is there. An existing file is replaced only with ``--force``, and only once the new
one is complete: it is written beside it under a temporary name (``NAME.partial``) and renamed
over it at the end. Without ``--force`` the rename refuses to replace a file that appeared
meanwhile, and the new one stays under its temporary name.
"""

from __future__ import annotations

import argparse
import contextlib
import os
from pathlib import Path

from ._common import UsageError

PARTIAL = ".partial"


def add_force_option(parser: argparse.ArgumentParser, what: str = "the --out file") -> None:
    parser.add_argument(
        "--force",
        action="store_true",
        help=f"replace {what} if it exists (only once the new one is complete)",
    )


def check_file(path: Path, *, force: bool) -> None:
    """Raise :class:`UsageError` (plain words) unless ``path`` can be written as a new or replaced file."""
    if path.is_dir():
        raise UsageError(f"{path} is a directory; name a file to write")
    _check_folder(path.parent if str(path.parent) else Path("."))
    if path.exists() and not force:
        raise UsageError(f"{path} exists already; give --force to replace it (once the new one is complete)")
    if path.exists() and not os.access(path, os.W_OK):
        raise UsageError(f"{path} exists and cannot be replaced (no write permission)")


def check_folder(path: Path) -> None:
    """A folder to save into: an existing writable directory, or one that can be made."""
    if path.exists() and not path.is_dir():
        raise UsageError(f"{path} is a file, not a folder to save into")
    if path.is_dir():
        _check_folder(path)
        return
    _check_folder(path.parent if str(path.parent) else Path("."))


def _check_folder(folder: Path) -> None:
    if not folder.exists():
        raise UsageError(f"the folder {folder} does not exist")
    if not folder.is_dir():
        raise UsageError(f"{folder} is not a folder")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise UsageError(f"cannot write in {folder} (no permission)")


def partial_path(path: Path) -> Path:
    """Where the new file is written until it is complete: beside it, so the rename cannot cross disks.

    ``NAME.partial``, or ``NAME.2.partial``… when an earlier run left one (its data is not touched).
    """
    for n in range(1, 1000):
        candidate = path.with_name(path.name + (PARTIAL if n == 1 else f".{n}{PARTIAL}"))
        if not candidate.exists():
            return candidate
    raise UsageError(f"{path}: a thousand unfinished {PARTIAL} files lie beside it; remove some")


def settle(partial: Path, path: Path, *, force: bool) -> Path:
    """Move the complete ``partial`` to ``path``; the name it ends up under.

    With ``force`` an existing ``path`` is replaced in one step. Without it, a ``path`` that
    appeared meanwhile is left alone and the new file keeps its temporary name.
    """
    if force:
        os.replace(partial, path)
        return path
    try:
        os.link(partial, path)  # fails if path exists: never replaces anything
    except FileExistsError:
        return partial
    except OSError:  # no hard links here (some network or FAT file systems)
        if path.exists():
            return partial
        os.replace(partial, path)
        return path
    partial.unlink()
    return path


def write_whole(path: Path, data: bytes, *, force: bool) -> Path:
    """Write ``data`` to ``path`` through its temporary name; the name it ends up under."""
    partial = partial_path(path)
    try:
        with open(partial, "xb") as f:
            f.write(data)
    except BaseException:
        with contextlib.suppress(OSError):
            partial.unlink()
        raise
    return settle(partial, path, force=force)

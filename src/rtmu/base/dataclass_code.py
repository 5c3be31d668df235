"""Keep the code that ``dataclasses`` writes for each class between runs, as Python keeps bytecode.

Every ``@dataclass`` writes its ``__init__``, ``__repr__``, ``__eq__`` and — frozen —
``__setattr__``, ``__delattr__`` and ``__hash__`` as source text and compiles each one at every
start. The window defines 318 of them on its way to the first frame: 1 842 compilations, 0.17 s of
CPU of a 1.1 s launch — more than GTK's own import. Compiling the same text always gives the same
code, so :func:`install` gives the ``dataclasses`` module an ``exec`` that compiles a text once and
then reuses it, and :func:`save` keeps what was compiled in the user's cache for the next start.
The cache only ever spares a compilation: a missing, stale or damaged file costs one, never a
difference in the classes made (the text, not the class, is the key).
"""

from __future__ import annotations

import atexit
import importlib.util
import marshal
import os
import sys
from pathlib import Path
from types import CodeType
from typing import Any

from .xdg import CACHE, xdg_home

FORMAT = "v2"
"""In the file's name: a cache written by an earlier RTMU (v1 compiled with the wrong flags) is
never read."""
MAX_ENTRIES = 6_000
"""More than that on disk (a long history of edited classes), and a save keeps this run's only."""


class Table:
    """The cache as read: digest of a method text → (offset, length) of its marshalled code in one
    blob. One large buffer, not 1 400 small ones among the modules being imported, so letting go
    of it (:func:`release`) gives its memory back rather than leaving holes in the heap."""

    def __init__(self, index: dict[bytes, tuple[int, int]] | None = None, blob: bytes = b"") -> None:
        self.index = index or {}
        self.blob = blob

    def get(self, key: bytes) -> bytes | None:
        where = self.index.get(key)
        return None if where is None else self.blob[where[0] : where[0] + where[1]]

    def entries(self) -> dict[bytes, bytes]:
        return {k: self.blob[o : o + n] for k, (o, n) in self.index.items()}

    def dumps(self) -> bytes:
        return marshal.dumps((self.index, self.blob))

    @classmethod
    def of(cls, entries: dict[bytes, bytes]) -> Table:
        index: dict[bytes, tuple[int, int]] = {}
        offset = 0
        for key, data in entries.items():
            index[key] = (offset, len(data))
            offset += len(data)
        return cls(index, b"".join(entries.values()))

    @classmethod
    def read(cls, path: Path) -> Table:
        """The file's table; an empty one when there is none or it is damaged (compile as usual)."""
        try:
            index, blob = marshal.loads(path.read_bytes())
        except (OSError, ValueError, EOFError, TypeError):
            return cls()
        if not isinstance(index, dict) or not isinstance(blob, bytes):
            return cls()
        size = len(blob)
        good: dict[bytes, tuple[int, int]] = {}
        for key, where in index.items():  # a damaged file may hold anything that marshal can
            if isinstance(key, bytes) and isinstance(where, tuple) and len(where) == 2:
                offset, length = where
                if (
                    isinstance(offset, int)
                    and isinstance(length, int)
                    and 0 <= offset <= offset + length <= size
                ):
                    good[key] = (offset, length)
        return cls(good, blob)


class _Cache:
    """This process's state: the table read (once, at the first class), what it compiled."""

    def __init__(self) -> None:
        self.stored = Table()
        self.new: dict[bytes, bytes] = {}
        self.used: set[bytes] = set()
        self.installed = self.loaded = self.released = False


_cache = _Cache()


def cache_file() -> Path:
    """``$XDG_CACHE_HOME/rtmu/dataclass-code-<format>-<interpreter>-<bytecode magic>.marshal``."""
    root = xdg_home(CACHE)
    tag = f"{sys.implementation.cache_tag}-{importlib.util.MAGIC_NUMBER.hex()}"
    return Path(root) / "rtmu" / f"dataclass-code-{FORMAT}-{tag}.marshal"


def compiled_this_run() -> int:
    """How many method texts this process compiled (what the cache did not hold)."""
    return len(_cache.new)


def held_entries() -> int:
    """How many compilations the table read from the cache holds now (0 after :func:`release`)."""
    return len(_cache.stored.index)


def _cached_exec(source: Any, globals_: Any = None, locals_: Any = None) -> None:
    """``exec`` as ``dataclasses`` calls it (text, globals, namespace), with the compilation kept."""
    if not isinstance(source, str):
        exec(source, globals_, locals_)  # only the dataclasses module calls this
        return
    c = _cache
    if not c.loaded and not c.released:
        c.loaded = True
        c.stored = Table.read(cache_file())
    key = _blake2b(source.encode(), digest_size=20).digest()
    c.used.add(key)
    code = _unmarshalled(c.stored.get(key) or c.new.get(key))
    if code is None:
        # As dataclasses' own exec compiles it: without this module's ``from __future__`` flags
        # (inherited, they would leave ``__init__``'s annotations as strings).
        code = compile(source, "<string>", "exec", dont_inherit=True)
        c.new[key] = marshal.dumps(code)
    exec(code, globals_, locals_)  # compiled from dataclasses' own text


try:
    from _blake2 import blake2b as _blake2b  # hashlib's own blake2b, without loading OpenSSL (9 ms)
except ImportError:  # pragma: no cover - an interpreter built without it
    from hashlib import blake2b as _blake2b


def _unmarshalled(data: bytes | None) -> CodeType | None:
    if data is None:
        return None
    try:
        code = marshal.loads(data)
    except (ValueError, EOFError, TypeError):
        return None  # a damaged entry: compiled again
    return code if isinstance(code, CodeType) else None


def install(*, save_at_exit: bool = True) -> None:
    """Compile each dataclass method text once per user rather than once per start (idempotent).
    Call before the modules with the dataclasses are imported."""
    if _cache.installed:
        return
    _cache.installed = True
    import dataclasses  # here: ``rtmu --version`` and ``--help`` load cli (and this module) but no dataclass

    dataclasses.exec = _cached_exec  # type: ignore[attr-defined]  # shadows the builtin there only
    if save_at_exit:
        atexit.register(save)


def release() -> None:
    """Save now and let go of the table (1–2 MiB): for a process that has built its classes — the
    window once it settles. A class made later compiles as without the cache."""
    save()
    _cache.released = True
    _cache.stored = Table()


def save() -> bool:
    """Add what this run compiled to the cache file (read again, so entries another run wrote
    meanwhile stay; written atomically). True when written; a cache that cannot be written is skipped."""
    c = _cache
    if not c.new:
        return False
    path = cache_file()
    entries = {**Table.read(path).entries(), **c.new}
    if len(entries) > MAX_ENTRIES:
        entries = {k: v for k, v in entries.items() if k in c.used}
    import tempfile  # only a run that compiled something pays for it

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, temporary = tempfile.mkstemp(prefix=".dataclass-code-", dir=path.parent)
        try:
            with os.fdopen(fd, "wb") as out:
                out.write(Table.of(entries).dumps())
            os.replace(temporary, path)
        except BaseException:
            os.unlink(temporary)
            raise
    except OSError:
        return False
    c.new.clear()
    return True

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
import dataclasses
import hashlib
import importlib.util
import marshal
import os
import sys
from pathlib import Path
from types import CodeType
from typing import Any

MAX_ENTRIES = 6_000
"""More than that on disk (a long history of edited classes), and a save keeps this run's only."""

_stored: dict[bytes, bytes] = {}
"""Digest of a method text → its code, marshalled, as read from the cache at the first class
(dropped by :func:`release` once a long-lived process has built its classes)."""
_new: dict[bytes, bytes] = {}
"""What this run compiled, marshalled, for :func:`save`."""
_used: set[bytes] = set()
_state = {"installed": False, "loaded": False, "released": False}


def cache_file() -> Path:
    """``$XDG_CACHE_HOME/rtmu/dataclass-code-<interpreter>-<bytecode magic>.marshal``."""
    root = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    tag = f"{sys.implementation.cache_tag}-{importlib.util.MAGIC_NUMBER.hex()}"
    return Path(root) / "rtmu" / f"dataclass-code-{tag}.marshal"


def compiled_this_run() -> int:
    """How many method texts this process compiled (what the cache did not hold)."""
    return len(_new)


def _digest(source: str) -> bytes:
    return hashlib.blake2b(source.encode(), digest_size=20).digest()


def _cached_exec(source: Any, globals_: Any = None, locals_: Any = None) -> None:
    """``exec`` as ``dataclasses`` calls it (text, globals, namespace), with the compilation kept."""
    if not isinstance(source, str):
        exec(source, globals_, locals_)  # only the dataclasses module calls this
        return
    if not _state["loaded"] and not _state["released"]:
        _state["loaded"] = True
        _stored.update(_read(cache_file()))
    key = _digest(source)
    _used.add(key)
    code = _unmarshalled(_stored.get(key) or _new.get(key))
    if code is None:
        code = compile(source, "<string>", "exec")
        _new[key] = marshal.dumps(code)
    exec(code, globals_, locals_)  # compiled from dataclasses' own text


def _unmarshalled(data: bytes | None) -> CodeType | None:
    if data is None:
        return None
    try:
        code = marshal.loads(data)
    except (ValueError, EOFError, TypeError):
        return None  # a damaged entry: compiled again
    return code if isinstance(code, CodeType) else None


def _read(path: Path) -> dict[bytes, bytes]:
    try:
        table = marshal.loads(path.read_bytes())
    except (OSError, ValueError, EOFError, TypeError):
        return {}  # none yet, or damaged: compile as usual
    if not isinstance(table, dict):
        return {}
    return {k: v for k, v in table.items() if isinstance(k, bytes) and isinstance(v, bytes)}


def install(*, save_at_exit: bool = True) -> None:
    """Compile each dataclass method text once per user rather than once per start (idempotent).
    Call before the modules with the dataclasses are imported."""
    if _state["installed"]:
        return
    _state["installed"] = True
    dataclasses.exec = _cached_exec  # type: ignore[attr-defined]  # shadows the builtin there only
    if save_at_exit:
        atexit.register(save)


def release() -> None:
    """Save now and let go of the table (1–2 MiB): for a process that has built its classes — the
    window once it settles. A class made later compiles as without the cache."""
    save()
    _state["released"] = True
    _stored.clear()


def save() -> bool:
    """Add what this run compiled to the cache file (read again, so entries another run wrote
    meanwhile stay; written atomically). True when written; a cache that cannot be written is skipped."""
    if not _new:
        return False
    path = cache_file()
    table = {**_read(path), **_new}
    if len(table) > MAX_ENTRIES:
        table = {k: v for k, v in table.items() if k in _used}
    import tempfile  # only a run that compiled something pays for it

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, temporary = tempfile.mkstemp(prefix=".dataclass-code-", dir=path.parent)
        try:
            with os.fdopen(fd, "wb") as out:
                marshal.dump(table, out)
            os.replace(temporary, path)
        except BaseException:
            os.unlink(temporary)
            raise
    except OSError:
        return False
    _new.clear()
    return True

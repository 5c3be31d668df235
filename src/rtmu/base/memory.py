"""Giving freed memory back to the system: glibc keeps a thread's freed heap for that thread's next
allocations, and a burst of work on a helper thread — decoding the map, rendering its tiles — left
megabytes of it resident for the window's whole life (issue 28: RSS; 4 MiB on the office map)."""

from __future__ import annotations

import ctypes
import ctypes.util

_trim: list[object] = []


def give_back() -> bool:
    """Return the heap's free pages to the system now (``malloc_trim``, a few ms); False where the C
    library has no such call (then nothing happens). Call it after a burst, on the thread that made it."""
    if not _trim:
        try:
            libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
            _trim.append(getattr(libc, "malloc_trim", None))
        except OSError:
            _trim.append(None)
    trim = _trim[0]
    if trim is None:
        return False
    trim(0)  # type: ignore[operator]
    return True

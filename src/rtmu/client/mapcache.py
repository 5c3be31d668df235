"""The last map a session loaded, kept by the server's map identity so a reconnect costs no download.

Why: a map is the biggest thing a server sends (megabytes, seconds on Wi-Fi), and links that drop
and come back are the normal case for a robot on the move. ARIA's ``getMapId`` names the map file
with its MD5 checksum, size and time; while it says the same, the map is the same — across
reconnects and spurious ``mapUpdated`` broadcasts. A changed map has a new checksum and is loaded
again. Without ``getMapId`` (or with an empty identity) nothing is cached: a name alone cannot tell
that the file changed while we were away.

Failures whose cause is the map itself (too large, malformed) are kept too: a hostile or broken map
is not fetched again on every reconnect, only when the server says it changed.

:class:`SharedMaps` does the same across the sessions of one process: a fleet's robots usually
share one map file (same name, MD5, size and time), and twenty sessions downloading and parsing it
at once made a fleet's start-up slow and fragile. The first session to ask downloads it; the others
wait for that and take the same (immutable) map.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import threading
from collections import OrderedDict
from dataclasses import dataclass

from ..protocol.errors import ProtocolError
from ..protocol.payloads.map import MapId
from ..values.state import MapModel
from .connection import AriaClient
from .errors import ClientError

MapKey = tuple[str, int, str, str, int, int]
"""host, port, file name, checksum (hex), size, time."""
ContentKey = tuple[str, str, int, int]
"""file name, checksum (hex), size, time: the map whichever server sends it."""
SHARED_KEEP = 4
"""Maps a process keeps for sharing (a fleet on more maps than this downloads the oldest again)."""
SHARED_WAIT = 300.0
"""At most this long a session waits for another's download of the same map before fetching its own."""


def content_key(key: MapKey | None) -> ContentKey | None:
    return None if key is None else (key[2], key[3], key[4], key[5])


async def map_key(client: AriaClient, host: str, port: int, timeout: float) -> MapKey | None:
    """The identity of the server's current map, or None when it cannot tell one."""
    if not client.supports("getMapId"):
        return None
    with contextlib.suppress(ClientError, ProtocolError):
        typed = (await client.request_once("getMapId", timeout=timeout)).decode()
        if isinstance(typed, MapId) and (typed.checksum or typed.size or typed.mtime):
            return (host, port, typed.file_name, typed.checksum.hex(), typed.size, typed.mtime)
    return None


@dataclass
class MapCache:
    """One entry: the last map (or map-caused failure) with the identity it was loaded under."""

    key: MapKey | None = None
    model: MapModel | None = None

    def get(self, key: MapKey | None) -> MapModel | None:
        return self.model if key is not None and key == self.key else None

    def put(self, key: MapKey | None, model: MapModel) -> None:
        if key is not None:
            self.key, self.model = key, model


class SharedMaps:
    """Ready maps by content, shared by the sessions of one process; each map downloaded once.

    Thread-safe: every robot session runs on its own network thread. Only ready maps are
    shared; after a failed download each waiting session fetches the map itself.
    """

    def __init__(self, keep: int = SHARED_KEEP) -> None:
        self.keep = keep
        self._lock = threading.Lock()
        self._ready: OrderedDict[ContentKey, MapModel] = OrderedDict()
        self._loading: dict[ContentKey, concurrent.futures.Future[MapModel | None]] = {}
        self.downloads = 0
        """Downloads begun through :meth:`claim` (the figure a fleet's start-up test reads)."""

    def claim(
        self, key: ContentKey
    ) -> tuple[MapModel | None, concurrent.futures.Future[MapModel | None] | None]:
        """``(map, None)``: here it is. ``(None, future)``: another session is loading it, await
        :meth:`wait`. ``(None, None)``: the caller downloads it and must call :meth:`finish`."""
        with self._lock:
            found = self._ready.get(key)
            if found is not None:
                self._ready.move_to_end(key)
                return found, None
            pending = self._loading.get(key)
            if pending is not None:
                return None, pending
            self._loading[key] = concurrent.futures.Future()
            self.downloads += 1
            return None, None

    def finish(self, key: ContentKey, model: MapModel | None) -> None:
        """The claimed download ended: ``model`` when it is a ready map, else None (waiters fetch it)."""
        with self._lock:
            pending = self._loading.pop(key, None)
            if model is not None:
                self._ready[key] = model
                while len(self._ready) > self.keep:
                    self._ready.popitem(last=False)
        if pending is not None and not pending.done():
            pending.set_result(model)

    @staticmethod
    async def wait(pending: concurrent.futures.Future[MapModel | None]) -> MapModel | None:
        """Another session's download, awaited from this session's loop (None: fetch it yourself)."""
        with contextlib.suppress(TimeoutError, concurrent.futures.CancelledError):
            # shielded: this session going away must not cancel the download the others wait for
            return await asyncio.wait_for(asyncio.shield(asyncio.wrap_future(pending)), SHARED_WAIT)
        return None

"""The last map a session loaded, kept by the server's map identity so a reconnect costs no download.

Why: a map is the biggest thing a server sends (megabytes, seconds on Wi-Fi), and links that drop
and come back are the normal case for a robot on the move. ARIA's ``getMapId`` names the map file
with its MD5 checksum, size and time; while it says the same, the map is the same — across
reconnects and spurious ``mapUpdated`` broadcasts. A changed map has a new checksum and is loaded
again. Without ``getMapId`` (or with an empty identity) nothing is cached: a name alone cannot tell
that the file changed while we were away.

Failures whose cause is the map itself (too large, malformed) are kept too: a hostile or broken map
is not fetched again on every reconnect, only when the server says it changed.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass

from ..protocol.errors import ProtocolError
from ..protocol.payloads.map import MapId
from ..state import MapModel
from .connection import AriaClient
from .errors import ClientError

MapKey = tuple[str, int, str, str, int, int]
"""host, port, file name, checksum (hex), size, time."""


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

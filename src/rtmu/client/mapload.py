"""Download the server's map into ``rtmu.mapfile.MapData``: one function the session and ``rtmu map`` share.

``getMapBinary`` is preferred (geometry as int32 blocks: about 5× fewer bytes
and packets than text); ``getMap`` is the fallback, or forced with
``prefer_binary=False``. Packets go straight into the protocol layer's bounded
assemblers; the (CPU-heavy) conversion to arrays runs in an executor so the
network loop keeps its timing, and is bounded by :data:`CONVERT_TIMEOUT`.
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..mapfile.errors import MapFormatError
from ..protocol.errors import ProtocolError
from ..protocol.payloads.map import MapName
from ..protocol.payloads.mapstream import MapBinaryAssembler, MapTextAssembler
from .connection import REPLY_TIMEOUT, AriaClient
from .errors import ClientError, ClientTimeout, NotSupported, ProtocolFault


@dataclass
class Download:
    data: Any | None
    """``rtmu.mapfile.MapData``, or None when the server has no map."""
    name: str
    """The server's map file name (``getMapName``), may be empty."""
    source: str
    """``getMapBinary`` or ``getMap``."""
    packets: int


def map_source(client: AriaClient, prefer_binary: bool = True) -> str | None:
    if prefer_binary and client.supports("getMapBinary"):
        return "getMapBinary"
    if client.supports("getMap"):
        return "getMap"
    return None


async def map_name(client: AriaClient, timeout: float = REPLY_TIMEOUT) -> str:
    if not client.supports("getMapName"):
        return ""
    with contextlib.suppress(ClientError, ProtocolError):
        typed = (await client.request_once("getMapName", timeout=timeout)).decode()
        if isinstance(typed, MapName):
            return typed.file_name
    return ""


CONVERT_TIMEOUT = 60.0
"""At most this long for the packets → arrays conversion (0.15 s for a million points)."""


async def download_map(
    client: AriaClient,
    *,
    prefer_binary: bool = True,
    timeout: float = REPLY_TIMEOUT,
    progress: Callable[[int], None] | None = None,
    convert_timeout: float = CONVERT_TIMEOUT,
) -> Download:
    """The whole map; ``timeout`` bounds the wait for each packet. Raises ClientError subclasses only.

    A map the server got wrong (a bad header, broken binary blocks, a line break inside a
    line) is a :class:`ProtocolFault` saying why — never a bare ``MapFormatError`` that would
    leave a window "loading" for ever or print a traceback.
    """
    source = map_source(client, prefer_binary)
    if source is None:
        raise NotSupported("getMap", "this server offers no map (neither getMapBinary nor getMap)")
    name = await map_name(client, timeout)
    assembler: MapBinaryAssembler | MapTextAssembler = (
        MapBinaryAssembler() if source == "getMapBinary" else MapTextAssembler()
    )
    count = 0
    async for _ in client.stream(source, timeout=timeout, until=assembler.feed):
        count += 1
        if progress is not None and count % 200 == 0:
            progress(count)
    try:
        async with asyncio.timeout(convert_timeout):
            data = await asyncio.get_running_loop().run_in_executor(None, assembled_map, assembler)
    except TimeoutError:
        raise ClientTimeout(
            f"converting the map from {source!r} took more than {convert_timeout:g} s"
        ) from None
    except (ProtocolError, MapFormatError, ValueError) as exc:
        raise ProtocolFault(f"the map from {source!r} is malformed: {exc}") from None
    return Download(data, name, source, count)


def assembled_map(assembler: MapBinaryAssembler | MapTextAssembler) -> Any | None:
    """A complete assembler → ``MapData`` (None: the server has no map)."""
    from .. import mapfile as maps

    result = assembler.result()
    if not result.has_map:
        return None
    if isinstance(assembler, MapBinaryAssembler):
        return maps.from_stream(result.header_lines, result.segments, result.points)  # type: ignore[union-attr]
    return maps.parse_map(result.text, source="<getMap>")  # type: ignore[union-attr]

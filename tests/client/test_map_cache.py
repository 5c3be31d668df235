"""A reconnect never downloads the same map again; a changed map is downloaded again.

The server answers ``getMapId`` (file, MD5, size, time) as ARIA's does; the test counts the map
requests it receives.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable

from rtmu.client.lease import DriveLease
from rtmu.client.session import Session, SessionConfig

from .endless_maps import map_id_server
from .servers import TestServer, run


def _count(server: TestServer, name: str) -> int:
    return sum(1 for r in server.received if r.name == name)


async def _until(condition: Callable[[], bool], timeout: float = 10.0) -> None:
    async with asyncio.timeout(timeout):
        while not condition():
            await asyncio.sleep(0.02)


def test_reconnect_keeps_the_map_and_a_changed_map_is_loaded_again() -> None:
    async def go() -> None:
        server = map_id_server()
        await server.start()
        session = Session(DriveLease(), lambda change: None, config=SessionConfig())
        try:
            await session.connect("127.0.0.1", server.port, auto_reconnect=True)
            first = await asyncio.wait_for(session.load_map(), 10)
            assert first.state == "ready" and _count(server, "getMapBinary") == 1

            server.kill(server.sides[0])  # the link drops; the session reconnects by itself
            await _until(
                lambda: len(server.sides) == 2 and session.connected and _count(server, "getMapId") >= 2
            )
            await _until(lambda: session.map_downloads_skipped >= 1)
            assert _count(server, "getMapBinary") == 1, "the same map was downloaded again"
            assert session._map is first  # the very same map, no new generation for the view

            server.map_checksum = bytes(16)  # type: ignore[attr-defined]  # the map file changed
            server.broadcast("mapUpdated")
            await _until(lambda: _count(server, "getMapBinary") == 2)
            await _until(lambda: session._map.state == "ready" and session._map.generation > first.generation)
        finally:
            await session.disconnect()
            await server.stop()

    run(go(), timeout=40)


def test_without_a_map_id_every_connection_loads_the_map() -> None:
    """A name alone cannot tell that the file changed while we were away: no cache then."""

    async def go() -> None:
        server = TestServer()  # no getMapId
        await server.start()
        session = Session(DriveLease(), lambda change: None, config=SessionConfig())
        try:
            await session.connect("127.0.0.1", server.port, auto_reconnect=True)
            await asyncio.wait_for(session.load_map(), 10)
            server.kill(server.sides[0])
            await _until(lambda: _count(server, "getMapBinary") == 2)
            assert session.map_downloads_skipped == 0
        finally:
            await session.disconnect()
            await server.stop()

    run(go(), timeout=40)

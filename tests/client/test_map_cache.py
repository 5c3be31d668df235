"""A reconnect never downloads the same map again; a changed map is downloaded again.

The server answers ``getMapId`` (file, MD5, size, time) as ARIA's does; the test counts the map
requests it receives.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable

from rtmu.client.lease import DriveLease
from rtmu.client.mapcache import SharedMaps
from rtmu.client.session import Session, SessionConfig
from rtmu.values.intents import LoadMap
from rtmu.values.target import Target

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
            await session.connect(Target("127.0.0.1", server.port, auto_reconnect=True))
            first = await asyncio.wait_for(session.dispatch(LoadMap()), 10)
            assert first.state == "ready" and _count(server, "getMapBinary") == 1

            server.kill(server.sides[0])  # the link drops; the session reconnects by itself
            await _until(
                lambda: len(server.sides) == 2 and session.connected and _count(server, "getMapId") >= 2
            )
            await _until(lambda: session.maps.downloads_skipped >= 1)
            assert _count(server, "getMapBinary") == 1, "the same map was downloaded again"
            assert session.map is first  # the very same map, no new generation for the view

            server.map_checksum = bytes(16)  # type: ignore[attr-defined]  # the map file changed
            server.broadcast("mapUpdated")
            await _until(lambda: _count(server, "getMapBinary") == 2)
            await _until(lambda: session.map.state == "ready" and session.map.generation > first.generation)
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
            await session.connect(Target("127.0.0.1", server.port, auto_reconnect=True))
            await asyncio.wait_for(session.dispatch(LoadMap()), 10)
            server.kill(server.sides[0])
            await _until(lambda: _count(server, "getMapBinary") == 2)
            assert session.maps.downloads_skipped == 0
        finally:
            await session.disconnect()
            await server.stop()

    run(go(), timeout=40)


def test_sessions_sharing_a_map_download_it_once_and_a_different_map_is_not_shared() -> None:
    """A fleet's robots on one map file: one session downloads it, the others take that same map."""

    async def go() -> None:
        servers = [map_id_server() for _ in range(3)]
        for server in servers:
            await server.start()
        servers[2].map_checksum = bytes(16)  # type: ignore[attr-defined]  # another map of the same name
        shared = SharedMaps()
        config = SessionConfig(shared_maps=shared)
        sessions = [Session(DriveLease(), lambda change: None, config=config) for _ in servers]
        try:
            for session, server in zip(sessions, servers, strict=True):
                await session.connect(Target("127.0.0.1", server.port))
            maps = await asyncio.wait_for(asyncio.gather(*(s.dispatch(LoadMap()) for s in sessions)), 20)
            assert all(m.state == "ready" for m in maps)
            loads = [_count(server, "getMapBinary") for server in servers]
            assert sorted(loads[:2]) == [0, 1], f"the shared map was downloaded {sum(loads[:2])} times"
            assert loads[2] == 1, "a different map (other MD5) was taken from the shared one"
            assert maps[0].data is maps[1].data and maps[2].data is not maps[0].data
            assert [s.maps.downloads_shared for s in sessions] in ([1, 0, 0], [0, 1, 0])
            assert shared.downloads == 2
        finally:
            for session in sessions:
                await session.disconnect()
            for server in servers:
                await server.stop()

    run(go(), timeout=40)


def test_a_failed_shared_download_lets_the_waiting_session_fetch_its_own() -> None:
    async def go() -> None:
        servers = [map_id_server() for _ in range(2)]
        for server in servers:
            await server.start()
        shared = SharedMaps()
        key = ("test.map", bytes(range(16)).hex(), 1234, 1_700_000_000)
        assert shared.claim(key) == (None, None)  # a session elsewhere is downloading it …
        session = Session(DriveLease(), lambda change: None, config=SessionConfig(shared_maps=shared))
        try:
            await session.connect(Target("127.0.0.1", servers[0].port))
            loading = asyncio.ensure_future(session.dispatch(LoadMap()))
            await asyncio.sleep(0.3)
            assert not loading.done() and _count(servers[0], "getMapBinary") == 0, "it did not wait"
            shared.finish(key, None)  # … and failed
            got = await asyncio.wait_for(loading, 10)
            assert got.state == "ready" and _count(servers[0], "getMapBinary") == 1
        finally:
            await session.disconnect()
            for server in servers:
                await server.stop()

    run(go(), timeout=40)

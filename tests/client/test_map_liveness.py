"""A long map download without interleaved status must not be called a lost link (no reconnect)."""

from __future__ import annotations

import asyncio

from rtmu.client.lease import DriveLease
from rtmu.client.session import Session, SessionConfig
from rtmu.protocol.fields import FieldWriter
from rtmu.values.intents import LoadMap
from rtmu.values.target import Target

from .servers import MAP_LINES, SPECS, ServerSide, TestServer, run

SLOW_LINES = 150
"""Point lines sent 20 ms apart: 3 s of map with no status, longer than ``lost_after``."""


def _slow_map_server() -> TestServer:
    server = TestServer([s for s in SPECS if s[0] != "getMapBinary"])

    def slow_map(side: ServerSide, args: bytes) -> None:
        for task in side.subs.values():
            task.cancel()  # a server busy streaming its map sends no status meanwhile
        side.subs.clear()

        async def stream() -> None:
            head = MAP_LINES[: MAP_LINES.index("DATA") + 1]
            head = [f"NumPoints: {SLOW_LINES}" if x.startswith("NumPoints") else x for x in head]
            for line in head:
                side.conn.send_data("getMap", FieldWriter().string(line).bytes())
            for i in range(SLOW_LINES):
                side.conn.send_data("getMap", FieldWriter().string(f"{i} {i}").bytes())
                side.writer.write(side.conn.data_to_send())
                await asyncio.sleep(0.02)
            side.conn.send_data("getMap", b"\x00")
            side.conn.send_data("getMap", b"")
            side.writer.write(side.conn.data_to_send())

        asyncio.get_running_loop().create_task(stream())

    server.handlers["getMap"] = slow_map  # type: ignore[assignment]
    return server


def test_a_long_map_without_status_does_not_reconnect() -> None:
    async def go() -> None:
        server = _slow_map_server()
        await server.start()
        session = Session(DriveLease(), lambda change: None, config=SessionConfig(lost_after=1.0))
        try:
            await session.connect(Target("127.0.0.1", server.port, auto_reconnect=True))
            got = await asyncio.wait_for(session.dispatch(LoadMap()), 20)
            assert got.state == "ready", got.error
            assert len(server.sides) == 1  # the link was never called lost
        finally:
            await session.disconnect()
            await server.stop()

    run(go(), timeout=30)

"""The seam proof: a session fed recorded bytes builds the same robot and map as the live one did.

A live :class:`Session` watches the simulator (status, sonar, Wi-Fi, a map download) while
another connection drives the robot; a :class:`RecordingLink` keeps every byte the session
read. A fresh session then runs over a :class:`ReplayLink` of exactly those bytes — no
socket, no simulator — and must publish the same sequence of robot states and map states.
Both go through the same client code (``AriaClient`` over a ``Link``), so any part of the
session that depended on the socket, or on something other than the bytes, would show here.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable

from rtmu.client.call_values import Arg, Handler
from rtmu.client.connection import AriaClient
from rtmu.client.errors import ClientError
from rtmu.client.lease import DriveLease
from rtmu.client.link import Chunk, Link, RecordingLink, ReplayLink, open_tcp
from rtmu.client.session import Session, SessionConfig
from rtmu.package_data import project_map
from rtmu.protocol.payloads.drive import RatioDrive
from rtmu.sim import SimConfig, SimThread
from rtmu.values.state import MapChanged, MapModel, MapPhase, RobotChanged, RobotState, StateChange
from rtmu.values.target import Target

from .servers import run

ARENA = project_map("arena.map")
CONFIG = SessionConfig(ping_interval=3600.0, lost_after=3600.0)
"""One ping only (a timer that writes would make the replay wait on time, not on bytes)."""

Seen = list[tuple[str, object]]


def watched(changes: list[StateChange]) -> Seen:
    """The robot and map states in the order published (times are not compared: RobotState ignores them)."""
    out: Seen = []
    for change in changes:
        if isinstance(change, RobotChanged):
            out.append(("robot", change.value))
        elif isinstance(change, MapChanged):
            m: MapModel = change.value
            points = None if m.data is None else (m.data.num_points, m.data.num_lines)
            out.append(("map", (m.state, m.name, m.generation, m.received, m.error, points)))
    return out


def session_over(link_for: asyncio.Future[Link] | Link, changes: list[StateChange]) -> Session:
    """A session whose client runs over the given link (or the link the future will hold)."""

    async def opener(host: str, port: int) -> Link:
        return link_for if not isinstance(link_for, asyncio.Future) else await link_for

    def factory(on_close: Callable[[ClientError], None]) -> AriaClient:
        return AriaClient(on_close=on_close, opener=opener)

    return Session(DriveLease(), changes.append, config=CONFIG, client_factory=factory)


async def drive(port: int, seconds: float) -> None:
    """Another operator drives the robot in a slow arc, then stops (the watched session only watches)."""
    driver = AriaClient()
    await driver.connect(Target("127.0.0.1", port), timeout=5)
    try:
        for _ in range(int(seconds / 0.1)):
            driver.send(RatioDrive(40.0, 20.0, 50.0))
            await asyncio.sleep(0.1)
        driver.send(RatioDrive(0.0, 0.0, 0.0))
        driver.send("stop")
        await driver.flush()
    finally:
        await driver.disconnect()


async def until(predicate: Callable[[], bool], timeout: float = 10.0) -> None:
    async with asyncio.timeout(timeout):
        while not predicate():
            await asyncio.sleep(0.01)


async def record_live(port: int) -> tuple[list[Chunk], Seen]:
    changes: list[StateChange] = []
    recording: asyncio.Future[Link] = asyncio.get_running_loop().create_future()

    async def recorder() -> Link:
        link = RecordingLink(await open_tcp("127.0.0.1", port))
        recording.set_result(link)
        return link

    session = session_over(asyncio.ensure_future(recorder()), changes)
    await session.connect(Target("127.0.0.1", port, auto_reconnect=False))
    link = recording.result()
    assert isinstance(link, RecordingLink)
    await until(lambda: any(isinstance(c, MapChanged) and c.value.state is MapPhase.READY for c in changes))
    await drive(port, 1.5)
    await asyncio.sleep(0.5)  # status of the robot standing again
    # One synchronous moment: what was read so far, and what it made (handlers publish at once).
    chunks, seen = list(link.chunks), watched(changes)
    await session.close()
    return chunks, seen


async def replay(chunks: list[Chunk]) -> tuple[ReplayLink, Seen]:
    changes: list[StateChange] = []
    link = ReplayLink(chunks)
    session = session_over(link, changes)
    await session.connect(Target("replay", 0, auto_reconnect=False))
    await until(lambda: link.exhausted)
    await asyncio.sleep(0.3)  # the last chunk's waiters and the map conversion finish
    seen = watched(changes)
    await session.close()
    return link, seen


def test_a_replayed_session_builds_the_same_robot_and_map_as_the_live_one() -> None:
    async def go() -> None:
        with SimThread(SimConfig(port=0, map_path=ARENA, seed=1)) as sim:
            chunks, live = await record_live(sim.port)
        link, replayed = await replay(chunks)
        assert link.exhausted and len(chunks) > 20
        # The live run saw real motion, a battery, a mode, and a whole map.
        robots = [value for kind, value in live if kind == "robot"]
        assert isinstance(robots[-1], RobotState)
        assert len({(r.x, r.y, r.th) for r in robots}) > 5  # type: ignore[attr-defined]
        assert robots[-1].battery_v is not None and robots[-1].mode != ""
        ready = [value for kind, value in live if kind == "map" and value[0] is MapPhase.READY]  # type: ignore[index]
        assert ready and ready[-1][5][0] > 0  # type: ignore[index]
        # The replay, from the bytes alone, made exactly the same states in the same order — per part:
        # when the map's conversion (on an executor thread) ends among the status packets is up to
        # the scheduler, not to the bytes.
        for part in ("robot", "map"):
            assert [v for k, v in replayed if k == part] == [v for k, v in live if k == part], part

    run(go(), timeout=60)


def test_the_replay_waits_for_the_requests_its_replies_answer() -> None:
    """A reply is not handed over before the client has sent what it had sent live at that point."""

    async def go() -> None:
        link = ReplayLink([Chunk(b"first", 0), Chunk(b"second", 4)])
        assert await link.read(100) == b"first"
        reading = asyncio.create_task(link.read(100))
        await asyncio.sleep(0.01)
        assert not reading.done()  # the client has written nothing yet
        link.write(b"ask!")
        assert await asyncio.wait_for(reading, 1) == b"second"
        silent = asyncio.create_task(link.read(100))
        await asyncio.sleep(0.01)
        assert not silent.done()  # after the last chunk: open and silent, as a quiet server
        link.close()
        assert await asyncio.wait_for(silent, 1) == b""

    run(go())


def test_a_session_declares_its_subscriptions_as_data() -> None:
    """The session subscribes to what its table says, where offered, with the config's intervals."""

    async def go() -> None:
        requested: list[tuple[str, int]] = []

        class Watching(AriaClient):
            def request(self, name: str, interval_ms: int, handler: Handler, *args: Arg) -> None:
                requested.append((name, interval_ms))
                super().request(name, interval_ms, handler, *args)

        with SimThread(SimConfig(port=0, seed=1)) as sim:
            session = Session(
                DriveLease(),
                lambda change: None,
                config=SessionConfig(status_interval_ms=250, sonar_interval_ms=500, fetch_map=False),
                client_factory=lambda on_close: Watching(on_close=on_close),
            )
            try:
                await session.connect(Target("127.0.0.1", sim.port, auto_reconnect=False))
            except ClientError:
                raise
            finally:
                await session.close()
        names = [name for name, _ in requested]
        assert names[:4] == ["updateNumbers", "updateStrings", "getModeInfo", "sonarCurrent"]
        assert "mapUpdated" in names
        assert ("updateNumbers", 250) in requested and ("sonarCurrent", 500) in requested
        assert "update" not in names  # gives way to updateNumbers

    run(go())

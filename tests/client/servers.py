"""Small ArNetworking servers for client tests, on real loopback sockets.

Built on the project's own sans-I/O ``ServerConnection``, so the bytes are real
protocol; the behaviour is scripted per test: answer normally, never answer,
inject garbage, close in the middle of a map. Everything listens on 127.0.0.1.
"""

from __future__ import annotations

import asyncio
import contextlib
import threading
import time
from collections.abc import Callable, Coroutine
from dataclasses import dataclass, field
from typing import Any, TypeVar

from rtmu.protocol.auth import UserTable
from rtmu.protocol.datalist import DataList
from rtmu.protocol.events import PeerShutdown, RequestOnce, RequestReceived, RequestStopped
from rtmu.protocol.fields import FieldWriter
from rtmu.protocol.payloads.drive import SafeDrive
from rtmu.protocol.payloads.robot import BatteryInfo, ModeInfo, UpdateNumbers, UpdateStrings
from rtmu.protocol.server_connection import ServerConnection, ServerState

SPECS = [
    ("updateNumbers", "robot numbers", "none", "numbers", "RobotInfo", "RETURN_SINGLE"),
    ("updateStrings", "robot strings", "none", "strings", "RobotInfo", "RETURN_SINGLE"),
    ("batteryInfo", "battery", "none", "levels", "RobotInfo", "RETURN_SINGLE"),
    ("getModeInfo", "mode", "none", "mode", "RobotInfo", "RETURN_SINGLE"),
    ("stop", "stop", "none", "none", "Stop", "RETURN_NONE"),
    ("ratioDrive", "drive", "trans rot throttle", "none", "Movement", "RETURN_NONE"),
    ("setSafeDrive", "safe", "ubyte", "none", "UnsafeMovement", "RETURN_NONE"),
    ("getSafeDrive", "safe?", "none", "ubyte", "Movement", "RETURN_SINGLE"),
    ("turnByAngle", "turn", "double", "none", "Movement", "RETURN_NONE"),
    ("moveDist", "move", "double", "none", "Movement", "RETURN_NONE"),
    ("getMapName", "map name", "none", "string", "Map", "RETURN_SINGLE"),
    ("getMap", "map text", "none", "lines", "Map", "RETURN_UNTIL_EMPTY"),
    ("getMapBinary", "map binary", "none", "lines+blocks", "Map", "RETURN_UNTIL_EMPTY"),
    ("mapUpdated", "map changed", "none", "none", "Map", "RETURN_SINGLE"),
    ("getPictureCam1", "picture", "ubyte quality", "w h jpeg", "Video", "RETURN_SINGLE"),
]

MAP_LINES = [
    "2D-Map",
    "MinPos: 0 0",
    "MaxPos: 3000 2000",
    "NumPoints: 2",
    "LineMinPos: 0 0",
    "LineMaxPos: 3000 2000",
    "NumLines: 2",
    "LINES",
    "0 0 3000 0",
    "3000 0 3000 2000",
    "DATA",
    "100 200",
    "300 400",
]

Reply = list[bytes] | None
JPEG = b"\xff\xd8JPEG\xff\xd9"
T = TypeVar("T")


def run(coro: Coroutine[Any, Any, T], timeout: float = 15.0) -> T:
    """``asyncio.run`` with a hard timeout, so a broken test fails instead of hanging."""

    async def bounded() -> T:
        async with asyncio.timeout(timeout):
            return await coro

    return asyncio.run(bounded())


OnceHandler = Callable[["ServerSide", bytes], Reply]


def in_one_write(*packets: tuple[str, bytes]) -> OnceHandler:
    """A handler answering with ``packets`` — any data names, in this order — in one write, so the client
    reads them together: for the races between an answer and the broadcast right behind it."""

    def answer(side: ServerSide, _args: bytes) -> Reply:
        for name, payload in packets:
            side.conn.send_data(name, payload)
        return []  # all in the connection's buffer: ``TestServer.reply`` writes them in one write

    return answer


def _numbers(state: dict[str, float]) -> bytes:
    return UpdateNumbers(
        state.get("battery", 12.5),
        int(state.get("x", 0)),
        int(state.get("y", 0)),
        int(state.get("th", 0)),
        int(state.get("vel", 0)),
        int(state.get("rot_vel", 0)),
        0,
        25,
    ).encode()


def text_map_packets(lines: list[str]) -> list[bytes]:
    return [FieldWriter().string(line).bytes() for line in lines] + [b"\x00", b""]


def binary_map_packets(lines: list[str]) -> list[bytes]:
    head = lines[: lines.index("LINES")]
    segs = [tuple(map(int, line.split())) for line in lines[lines.index("LINES") + 1 : lines.index("DATA")]]
    pts = [tuple(map(int, line.split())) for line in lines[lines.index("DATA") + 1 :]]
    out = [FieldWriter().string(line).bytes() for line in head]
    out.append(FieldWriter().string("LINES").bytes())
    w = FieldWriter().byte4(len(segs))
    for s in segs:
        for v in s:
            w.byte4(v)
    out += [w.bytes(), FieldWriter().byte4(0).bytes(), FieldWriter().string("DATA").bytes()]
    w = FieldWriter().byte4(len(pts))
    for p in pts:
        for v in p:
            w.byte4(v)
    out += [w.bytes(), FieldWriter().byte4(0).bytes(), b""]
    return out


@dataclass
class Received:
    at: float
    name: str
    args: bytes
    kind: str = "once"
    side: int = 0
    """Which connection (index into ``TestServer.sides``) it came on."""


@dataclass
class ServerSide:
    """What one client connection's server end holds."""

    conn: ServerConnection
    writer: asyncio.StreamWriter
    subs: dict[str, asyncio.Task[None]] = field(default_factory=dict)


class TestServer:
    """A scripted ArNetworking server. ``handlers[name](side, args)`` returns reply payloads."""

    __test__ = False  # not a pytest class

    def __init__(
        self,
        specs: list[tuple[str, str, str, str, str, str]] | None = None,
        users: UserTable | None = None,
        *,
        silent: bool = False,
        map_lines: list[str] | None = None,
    ) -> None:
        self.datalist = DataList.build(specs or SPECS)
        self.users = users
        self.silent = silent
        """Accept connections and never send a byte."""
        self.map_lines = MAP_LINES if map_lines is None else map_lines
        self.state: dict[str, float] = {"x": 1000, "y": 2000, "th": 90, "battery": 12.5}
        self.strings = ("Stopped", "Stop", "Stopped")
        self.safe = True
        self.received: list[Received] = []
        self.sides: list[ServerSide] = []
        self.handlers: dict[str, OnceHandler] = {
            "updateNumbers": lambda s, a: [_numbers(self.state)],
            "updateStrings": lambda s, a: [UpdateStrings(*self.strings).encode()],
            "batteryInfo": lambda s, a: [BatteryInfo(11.5, 11.0, False).encode()],
            "getModeInfo": lambda s, a: [ModeInfo("stop").encode()],
            "getSafeDrive": lambda s, a: [SafeDrive(self.safe).encode()],
            "setSafeDrive": self._set_safe,
            "getMapName": lambda s, a: [FieldWriter().string("test.map").bytes()],
            "getMap": lambda s, a: text_map_packets(self.map_lines) if self.map_lines else [b"\x00"],
            "getMapBinary": lambda s, a: binary_map_packets(self.map_lines) if self.map_lines else [b"\x00"],
            "getPictureCam1": lambda s, a: [FieldWriter().ubyte2(2).ubyte2(1).bytes() + JPEG],
        }
        self._server: asyncio.base_events.Server | None = None
        self.port = 0
        self.hearing = asyncio.Event()
        """Cleared by :meth:`deafen`: the server keeps sending but reads nothing more."""
        self.hearing.set()
        self.admitting = asyncio.Event()
        """Cleared by :meth:`hold_logins`: new connections wait before the server says a word."""
        self.admitting.set()
        self.on_once: Callable[[ServerSide, str, bytes], None] | None = None

    def _set_safe(self, side: ServerSide, args: bytes) -> Reply:
        self.safe = bool(args[:1] != b"\x00")
        return None

    async def start(self) -> int:
        self._loop = asyncio.get_running_loop()
        self._server = await asyncio.start_server(self._serve, "127.0.0.1", 0)
        self.port = self._server.sockets[0].getsockname()[1]
        return self.port

    async def stop(self) -> None:
        if self._server is not None:
            self._server.close()
        for side in list(self.sides):
            self.kill(side)
        if self._server is not None:
            with contextlib.suppress(Exception):
                await asyncio.wait_for(self._server.wait_closed(), 1)

    def deafen(self) -> None:
        """Stop reading requests (like a server whose input thread hangs); subscriptions go on.

        Thread-safe: runs on the server's loop.
        """
        self._loop.call_soon_threadsafe(self.hearing.clear)

    def undeafen(self) -> None:
        self._loop.call_soon_threadsafe(self.hearing.set)

    def hold_logins(self) -> None:
        """New connections are accepted but wait (no introduction) until :meth:`admit_logins`."""
        self._loop.call_soon_threadsafe(self.admitting.clear)

    def admit_logins(self) -> None:
        self._loop.call_soon_threadsafe(self.admitting.set)

    def kill(self, side: ServerSide) -> None:
        """Drop a connection abruptly (no SHUTDOWN), like a crashed server. Server loop only."""
        for task in side.subs.values():
            task.cancel()
        transport = side.writer.transport
        # One already closing (the client said goodbye) is going anyway; and asyncio's abort()
        # of a transport closed with output queued, once that output has left, raises.
        if not transport.is_closing():
            transport.abort()

    def names(self) -> list[str]:
        return [r.name for r in self.received]

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        side = ServerSide(ServerConnection(self.datalist, self.users), writer)
        self.sides.append(side)
        try:
            if self.silent:
                await reader.read()  # until the client goes away
                return
            await self.admitting.wait()
            writer.write(side.conn.data_to_send())
            while True:
                await self.hearing.wait()
                data = await reader.read(65536)
                if not data:
                    return
                for event in side.conn.receive_data(data):
                    self._handle(side, event)
                writer.write(side.conn.data_to_send())
                if side.conn.state in (ServerState.CLOSING, ServerState.CLOSED):
                    await asyncio.sleep(0.01)
                    writer.close()
                    return
        except (ConnectionError, asyncio.CancelledError):
            pass
        finally:
            for task in side.subs.values():
                task.cancel()
            with contextlib.suppress(Exception):
                writer.close()

    def _handle(self, side: ServerSide, event: object) -> None:
        now = time.monotonic()
        n = self.sides.index(side)
        if isinstance(event, RequestOnce):
            self.received.append(Received(now, event.name, event.args, side=n))
            if self.on_once is not None:
                self.on_once(side, event.name, event.args)
            self.reply(side, event.name, event.args)
        elif isinstance(event, RequestReceived):
            self.received.append(Received(now, event.name, event.args, f"request {event.interval_ms}", n))
            old = side.subs.pop(event.name, None)
            if old is not None:
                old.cancel()  # ARIA: a re-subscription gets no immediate reply
            else:
                self.reply(side, event.name, event.args)
            if event.interval_ms >= 0:
                side.subs[event.name] = asyncio.get_running_loop().create_task(
                    self._periodic(side, event.name, event.args, event.interval_ms)
                )
        elif isinstance(event, RequestStopped):
            self.received.append(Received(now, event.name, b"", "stop", n))
            task = side.subs.pop(event.name, None)
            if task is not None:
                task.cancel()
        elif isinstance(event, PeerShutdown):
            self.received.append(Received(now, "SHUTDOWN", b"", "control", n))

    def reply(self, side: ServerSide, name: str, args: bytes) -> None:
        handler = self.handlers.get(name)
        payloads = handler(side, args) if handler else None
        for payload in payloads or ():
            side.conn.send_data(name, payload)
        side.writer.write(side.conn.data_to_send())

    def broadcast(self, name: str, payload: bytes = b"") -> None:
        for side in self.sides:
            if side.conn.datalist.number(name) in side.conn.subscriptions:
                side.conn.send_data(name, payload)
                side.writer.write(side.conn.data_to_send())

    async def _periodic(self, side: ServerSide, name: str, args: bytes, interval_ms: int) -> None:
        while True:
            await asyncio.sleep(max(interval_ms, 10) / 1000)
            self.reply(side, name, args)


class ServerThread:
    """Runs a :class:`TestServer` on its own loop in a thread (for tests of the threaded runner)."""

    def __init__(self, server: TestServer) -> None:
        self.server = server
        self.loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self.loop.run_forever, name="test-server", daemon=True)

    def __enter__(self) -> TestServer:
        self._thread.start()
        self.call(self.server.start)
        return self.server

    def __exit__(self, *exc: object) -> None:
        with contextlib.suppress(Exception):
            self.call(self.server.stop)

        async def cancel_all() -> None:
            tasks = [t for t in asyncio.all_tasks() if t is not asyncio.current_task()]
            for task in tasks:
                task.cancel()
            await asyncio.gather(*tasks, return_exceptions=True)

        with contextlib.suppress(Exception):
            self.call(cancel_all)
        self.loop.call_soon_threadsafe(self.loop.stop)
        self._thread.join(5)
        self.loop.close()

    def call(self, fn: Callable[[], object]) -> object:
        """Run ``fn`` (sync, or returning a coroutine) on the server loop; wait up to 5 s."""

        async def run() -> object:
            result = fn()
            if asyncio.iscoroutine(result):
                result = await result
            return result

        return asyncio.run_coroutine_threadsafe(run(), self.loop).result(5)

"""ARIA's central server (``switchServer``: ``ArCentralManager``, one :mod:`.forwarder` per robot).

Robot servers connect OUT to the robot port (5000), log in as ordinary clients and ask ``switch`` once
with their name; the empty reply turns the socket round: the robot becomes the server on it, and a
:class:`~rtmu.sim.forwarder.Forwarder` logs in to it as a client (:mod:`rtmu.sim.switch` is the robot's
half) and serves it to operators on a port of its own: the central port + 1 and up (skipping ports in
use), or any free port when the central port is 0. Operators on the central port read ``clientList``
and hear ``clientAdded`` / ``clientRemoved``; a user file, when given, guards the central port and every
forwarder alike (ARIA's forwarders take the main server's users).

Bounded: robots (``max_robots``), operators per port, output per peer; a robot whose name (compared
case-insensitively) is already listed replaces the old connection, as ARIA's does. Listens on
127.0.0.1 unless told otherwise; the forwarders listen on the same host.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from pathlib import Path

from rtmu.protocol.auth import UserTable
from rtmu.protocol.datalist import DataList
from rtmu.protocol.errors import ProtocolError
from rtmu.protocol.events import LoginRefused, PeerShutdown, RequestOnce, RequestReceived, RequestStopped
from rtmu.protocol.packet import MAX_PAYLOAD, encode_packet
from rtmu.protocol.payloads.central import CentralEntry, ClientAdded, ClientList, ClientRemoved, SwitchRequest
from rtmu.protocol.server_connection import ServerConnection

from .forwarder import Forwarder
from .peers import KEY_RNG, MAX_OPERATORS, READ_CHUNK, Operator, Peer, serve_operator

log = logging.getLogger("rtmu.sim.central")

FORWARD_PORT_TRIES = 200
MAX_NAME = 511
"""ARIA reads a robot's name into 512 bytes: a longer one is cut there."""

OPERATOR_DATA = DataList.build(
    [
        (
            "clientList",
            "Lists the clients that are connected",
            "none",
            "ubyte2: numClients; repeating for <numClients> [string: hostname (empty means this host); "
            "ubyte2: port; string: robot name; string: flags; string: robot ip address]",
            "RobotInfo",
            "RETURN_SINGLE",
        ),
        (
            "clientAdded",
            "Broadcast when a client is added",
            "none",
            "string: hostname (empty means this host); ubyte2: port; string: robot name; string: flags; "
            "string: robot ip address",
            "RobotInfo",
            "RETURN_SINGLE",
        ),
        (
            "clientRemoved",
            "Broadcast when a client is removed",
            "none",
            "string: hostname (empty means this host); ubyte2: port; string: robot name; string: flags; "
            "string: robot ip address",
            "RobotInfo",
            "RETURN_SINGLE",
        ),
    ]
)
"""What operators see on the central port (ARIA's ``clientServer`` of ``switchServer``)."""

ROBOT_DATA = DataList.build(
    [
        (
            "switch",
            "switches the direction of the connection: the empty reply accepts the switch",
            "string: robotName",
            "empty packet",
            "RobotInfo",
            "RETURN_SINGLE",
        ),
        (
            "centralServerHeartbeat",
            "tells robots that this central server sends heartbeats",
            "none",
            "none",
            "RobotInfo",
            "RETURN_NONE",
        ),
    ]
)
"""What robots see on the robot port (ARIA's ``robotServer``)."""


@dataclass
class CentralConfig:
    host: str = "127.0.0.1"
    port: int = 7272
    """Operators' port; 0 picks a free one (and the forwarders then take free ports too)."""
    robot_port: int = 5000
    """Where robots switch to us (ARIA's default); 0 picks a free one."""
    max_robots: int = 100
    heartbeat_s: float = 1.0
    """How often ``centralServerHeartbeat`` goes to each robot that lists it."""
    robot_silence_s: float = 120.0
    """A robot that sends nothing (not even its 1 s ``centralHeartbeat``) this long is dropped and
    unlisted (ARIA's ``CentralServerFromRobotTimeoutInMins``, 2)."""
    login_timeout: float = 10.0
    """Seconds for a robot to ask ``switch``, and then to introduce itself and list its data."""
    users_path: Path | None = None
    """An ARIA user-info file for operators (central port and forwarders); None: anyone."""


class CentralServer:
    """``rtmu sim --central``: the operators' port, the robots' port and a forwarder per robot."""

    def __init__(self, config: CentralConfig | None = None) -> None:
        self.config = config or CentralConfig()
        self.port = 0
        self.robot_port = 0
        self.forwarders: list[Forwarder] = []
        self.operators: list[Operator] = []
        self._servers: list[asyncio.base_events.Server] = []
        self._tasks: set[asyncio.Task[None]] = set()
        self.switches = 0
        """Switch requests accepted (tests and logs)."""
        self.users = UserTable.load(self.config.users_path) if self.config.users_path else None
        self._switching = 0
        """Robot-port connections not yet switched (they count against ``max_robots``)."""

    async def start(self) -> None:
        cfg = self.config
        ops = await asyncio.start_server(self._accept_operator, cfg.host, cfg.port)
        self._servers.append(ops)
        self.port = ops.sockets[0].getsockname()[1]
        robots = await asyncio.start_server(self._accept_robot, cfg.host, cfg.robot_port)
        self._servers.append(robots)
        self.robot_port = robots.sockets[0].getsockname()[1]

    async def stop(self) -> None:
        """SHUTDOWN to every operator and robot, then close."""
        for server in self._servers:
            server.close()
        for fwd in list(self.forwarders):
            fwd.close()
        for op in list(self.operators):
            op.conn.shutdown()
            op.flush()
            op.close()
        self._servers.clear()
        await self._settle()

    def kill(self) -> None:
        """Die abruptly: every socket reset, nobody told (for lost-link tests)."""
        for server in self._servers:
            server.close()
        self._servers.clear()
        for op in list(self.operators):  # first: a dead process sends no clientRemoved as forwarders close
            op.abort()
        for fwd in list(self.forwarders):
            for op in fwd.operators:
                op.abort()
            fwd.robot.abort()
            fwd.close()

    async def _settle(self) -> None:
        tasks = [t for t in self._tasks if not t.done() and t is not asyncio.current_task()]
        if tasks:
            await asyncio.wait(tasks, timeout=1.0)

    def _track(self) -> asyncio.Task[None] | None:
        task = asyncio.current_task()
        if task is not None:
            self._tasks.add(task)
            task.add_done_callback(self._tasks.discard)
        return task

    def robots(self) -> list[CentralEntry]:
        """The robots operators can reach now, in the order they came."""
        return [f.entry for f in self.forwarders if f.connected]

    def client_list(self) -> bytes:
        """``clientList``: as many robots as one packet holds (ARIA's packet stops taking more there)."""
        entries = self.robots()
        while True:
            payload = ClientList(tuple(entries)).encode()
            if len(payload) <= MAX_PAYLOAD:
                return payload
            entries.pop()

    # -- operators on the central port ----------------------------------------------------
    async def _accept_operator(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        op = Operator(reader, writer, OPERATOR_DATA, self.users)
        if len(self.operators) >= MAX_OPERATORS:
            op.abort()
            return
        self.operators.append(op)
        self._track()
        try:
            await serve_operator(op, self._on_operator)
        except asyncio.CancelledError:
            pass
        finally:
            with contextlib.suppress(ValueError):
                self.operators.remove(op)

    def _on_operator(self, op: Operator, event: object) -> None:
        if isinstance(event, RequestReceived):
            op.subscriptions[event.number] = event.interval_ms
            if event.name == ClientList.DATA_NAME and event.new:
                op.conn.send_data(event.name, self.client_list())
        elif isinstance(event, RequestStopped):
            op.subscriptions.pop(event.number, None)
        elif isinstance(event, RequestOnce) and event.name == ClientList.DATA_NAME:
            op.conn.send_data(event.name, self.client_list())

    def _broadcast(self, name: str, payload: bytes) -> None:
        number = OPERATOR_DATA.number(name)
        assert number is not None
        packet = encode_packet(number, payload)
        for op in list(self.operators):
            if number in op.subscriptions:
                op.write(packet)

    # -- robots on the robot port ---------------------------------------------------------
    async def _accept_robot(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        peer = Peer(reader, writer)
        if len(self.forwarders) + self._switching >= self.config.max_robots:
            log.info("robot %s: already %d robots; closing it", peer.address, self.config.max_robots)
            peer.abort()
            return
        self._track()
        self._switching += 1
        try:
            name = await self._await_switch(peer)
        finally:
            self._switching -= 1
        if name is not None:
            await self._forward(peer, name[:MAX_NAME] or peer.address)

    async def _await_switch(self, peer: Peer) -> str | None:
        """Serve the robot port's login until ``switch`` is asked: the robot's name (None: it went)."""
        reader = peer.reader
        conn = ServerConnection(ROBOT_DATA, rng=KEY_RNG)
        peer.write(conn.data_to_send())
        name: str | None = None
        try:
            async with asyncio.timeout(self.config.login_timeout):
                while name is None:
                    data = await reader.read(READ_CHUNK)
                    if not data:
                        peer.abort()
                        return None
                    for event in conn.receive_data(data):
                        if isinstance(event, RequestOnce) and event.name == SwitchRequest.DATA_NAME:
                            try:
                                name = SwitchRequest.decode(event.args).robot_name
                            except ProtocolError:
                                name = ""
                            break
                        if isinstance(event, (LoginRefused, PeerShutdown)):
                            peer.write(conn.data_to_send())
                            peer.close()
                            return None
                    peer.write(conn.data_to_send())
        except (TimeoutError, ConnectionError, OSError, asyncio.CancelledError):
            peer.abort()
            return None
        conn.send_data(SwitchRequest.DATA_NAME)  # the empty acceptance; the socket turns round now
        peer.write(conn.data_to_send())
        return name

    async def _forward(self, peer: Peer, name: str) -> None:
        for old in [f for f in self.forwarders if f.name.lower() == name.lower()]:
            log.info("robot %r switched again; dropping its old connection", name)
            old.robot.abort()
            old.close()
        self.switches += 1
        cfg = self.config
        forwarder = Forwarder(
            peer,
            name,
            listen=self._listen,
            on_up=self.forwarder_up,
            on_down=self.forwarder_down,
            users=self.users,
            login_timeout=cfg.login_timeout,
            heartbeat_s=cfg.heartbeat_s,
            silence_timeout=cfg.robot_silence_s,
        )
        self.forwarders.append(forwarder)
        try:
            await forwarder.run()
        except asyncio.CancelledError:
            forwarder.close()

    async def _listen(
        self, accept: Callable[[asyncio.StreamReader, asyncio.StreamWriter], Awaitable[None]]
    ) -> asyncio.base_events.Server:
        """A port for a forwarder: the first free one above the central port (any, when that is 0)."""
        host = self.config.host
        if self.config.port == 0:
            return await asyncio.start_server(accept, host, 0)
        taken = {f.port for f in self.forwarders if f.port} | {self.port, self.robot_port}
        for port in range(self.port + 1, min(self.port + 1 + FORWARD_PORT_TRIES, 65536)):
            if port in taken:
                continue
            with contextlib.suppress(OSError):
                return await asyncio.start_server(accept, host, port)
        raise OSError(f"no free port above {self.port} to forward a robot on")

    def forwarder_up(self, forwarder: Forwarder) -> None:
        log.info("robot %r forwarded on port %d", forwarder.name, forwarder.port)
        self._broadcast(ClientAdded.DATA_NAME, ClientAdded(forwarder.entry).encode())

    def forwarder_down(self, forwarder: Forwarder) -> None:
        if forwarder not in self.forwarders:
            return
        self.forwarders.remove(forwarder)
        if forwarder.connected:
            forwarder.connected = False
            log.info("robot %r left", forwarder.name)
            self._broadcast(ClientRemoved.DATA_NAME, ClientRemoved(forwarder.entry).encode())

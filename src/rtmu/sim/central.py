"""ARIA's central server (``switchServer``: ``ArCentralManager`` + one ``ArCentralForwarder`` per robot).

Robot servers connect OUT to the robot port (5000), log in as ordinary clients and ask ``switch`` once
with their name; the empty reply turns the socket round: the robot becomes the server on it, and this
side logs in to it as a client (:mod:`rtmu.sim.switch` is the robot's half). Each robot is then served to
operators on a port of its own (the central port + 1 and up, or any free port when the central port is
0): a forwarder, not a byte pipe — it logs in to the robot once over the switched connection, offers the
robot's own data list to any number of operators, and relays their requests (one REQUEST to the robot
per data, at the shortest interval any operator asked for; REQUESTSTOP when the last one stops) and the
robot's packets back to the operators that asked for that data. Operators on the central port read
``clientList`` and hear ``clientAdded`` / ``clientRemoved``.

Everything is bounded: robots (``max_robots``), operators per port, output queued per peer; a robot that
asks for a name already taken replaces the old connection, as ARIA does. Listens on 127.0.0.1 only by
default; the forwarders listen on the same host.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import random
from collections.abc import Callable
from dataclasses import dataclass

from rtmu.protocol.client_connection import ClientConnection
from rtmu.protocol.commands import ServerCommand, is_control_command
from rtmu.protocol.datalist import DataList
from rtmu.protocol.errors import ProtocolError
from rtmu.protocol.events import (
    ClientIntroduced,
    DataListReady,
    LoginRefused,
    PeerShutdown,
    Rejected,
    RequestOnce,
    RequestReceived,
    RequestStopped,
)
from rtmu.protocol.packet import Packet, encode_packet
from rtmu.protocol.payloads.central import (
    CentralEntry,
    CentralServerHeartbeat,
    ClientAdded,
    ClientList,
    ClientRemoved,
    SwitchRequest,
)
from rtmu.protocol.payloads.control import Request, RequestStop
from rtmu.protocol.server_connection import ServerConnection, ServerState

log = logging.getLogger("rtmu.sim.central")

KEY_RNG = random.SystemRandom()
READ_CHUNK = 65536
MAX_QUEUED = 4 * 1024 * 1024
"""Output waiting for one peer beyond this gets it dropped (a reader that stopped reading)."""
MAX_OPERATORS = 64
"""Operators per port (the central port and each forwarder); one more is closed at once."""
FORWARD_PORT_TRIES = 200

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
    login_timeout: float = 10.0
    """Seconds for a robot to ask ``switch``, and then to introduce itself and list its data."""


class Peer:
    """One TCP peer with a sans-I/O codec: bounded output, abort on any trouble."""

    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.reader = reader
        self.writer = writer
        self.closed = False
        peer = writer.get_extra_info("peername")
        self.address = peer[0] if isinstance(peer, tuple) else str(peer)

    def write(self, data: bytes) -> None:
        if self.closed or not data:
            return
        transport = self.writer.transport
        if transport is None or transport.is_closing():
            self.abort()
            return
        if transport.get_write_buffer_size() + len(data) > MAX_QUEUED:
            log.info("peer %s: %d bytes queued and not read; dropping it", self.address, MAX_QUEUED)
            self.abort()
            return
        self.writer.write(data)

    def abort(self) -> None:
        if self.closed:
            return
        self.closed = True
        transport = self.writer.transport
        if transport is not None:
            transport.abort()

    def close(self) -> None:
        """Goodbye after what is queued (a SHUTDOWN already written)."""
        if self.closed:
            return
        self.closed = True
        with contextlib.suppress(Exception):
            self.writer.close()


class Operator(Peer):
    """An operator logged in to the central port or to a forwarder."""

    def __init__(
        self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter, datalist: DataList
    ) -> None:
        super().__init__(reader, writer)
        self.conn = ServerConnection(datalist, rng=KEY_RNG)
        self.subscriptions: dict[int, int] = {}
        self.asked_once: set[int] = set()
        """Data asked once: their replies (possibly many packets) come back to this operator."""

    def flush(self) -> None:
        self.write(self.conn.data_to_send())

    def wants(self, number: int) -> bool:
        return number in self.subscriptions or number in self.asked_once


async def serve_operator(
    op: Operator,
    on_event: Callable[[Operator, object], None],
) -> None:
    """Read ``op`` until it goes; every codec event goes to ``on_event``."""
    op.flush()  # the server INTRODUCTION
    try:
        while not op.closed:
            data = await op.reader.read(READ_CHUNK)
            if not data:
                break
            for event in op.conn.receive_data(data):
                if isinstance(event, (LoginRefused, PeerShutdown)):
                    op.flush()
                    return
                if isinstance(event, ClientIntroduced):
                    op.flush()
                on_event(op, event)
                if op.closed:
                    return
            op.flush()
            if op.conn.state in (ServerState.CLOSING, ServerState.CLOSED):
                return
    except (ConnectionError, OSError):
        pass
    finally:
        op.abort()


class Forwarder:
    """One switched robot: logged in to over its own socket, served to operators on its own port."""

    def __init__(self, central: CentralServer, robot: Peer, name: str) -> None:
        self.central = central
        self.robot = robot
        self.name = name
        self.port = 0
        self.connected = False
        self.conn = ClientConnection()
        self.datalist = DataList()
        self.operators: list[Operator] = []
        self._server: asyncio.base_events.Server | None = None
        self._forwarded: dict[int, int] = {}
        """Data number → the interval last asked of the robot for it."""
        self._tasks: set[asyncio.Task[None]] = set()
        self.packets_from_robot = 0

    @property
    def entry(self) -> CentralEntry:
        return CentralEntry("", self.port, self.name, "", self.robot.address)

    async def run(self) -> None:
        """Log in to the robot, open the forwarded port, then relay until the robot goes."""
        try:
            async with asyncio.timeout(self.central.config.login_timeout):
                await self._login()
            await self._listen()
        except (TimeoutError, ProtocolError, ConnectionError, OSError) as exc:
            log.info("robot %r: cannot forward it: %s", self.name, exc or type(exc).__name__)
            self.close()
            return
        self.connected = True
        self.central.forwarder_up(self)
        heartbeat = asyncio.get_running_loop().create_task(self._heartbeats())
        try:
            await self._relay()
        finally:
            heartbeat.cancel()
            self.close()

    async def _login(self) -> None:
        while True:
            data = await self.robot.reader.read(READ_CHUNK)
            if not data:
                raise ConnectionError("the robot closed the switched connection during login")
            events = self.conn.receive_data(data)
            self.robot.write(self.conn.data_to_send())
            for event in events:
                if isinstance(event, Rejected):
                    raise ConnectionError(f"the robot refused our login (reason {event.reason})")
                if isinstance(event, PeerShutdown):
                    raise ConnectionError("the robot shut the connection down during login")
                if isinstance(event, DataListReady):
                    self.datalist = event.datalist
                    return

    async def _listen(self) -> None:
        host = self.central.config.host
        if self.central.config.port == 0:
            self._server = await asyncio.start_server(self._accept, host, 0)
        else:
            port = self.central.port + 1
            for _ in range(FORWARD_PORT_TRIES):
                if port != self.central.robot_port and port not in self.central.ports_in_use():
                    with contextlib.suppress(OSError):
                        self._server = await asyncio.start_server(self._accept, host, port)
                        break
                port += 1
            if self._server is None:
                raise OSError(f"no free port for robot {self.name!r} above {self.central.port}")
        self.port = self._server.sockets[0].getsockname()[1]

    async def _relay(self) -> None:
        decoder = self.conn.decoder
        while not self.robot.closed:
            try:
                data = await self.robot.reader.read(READ_CHUNK)
            except (ConnectionError, OSError):
                return
            if not data:
                return
            for packet in decoder.feed(data):
                if packet.command == ServerCommand.SHUTDOWN:
                    return
                if is_control_command(packet.command):
                    continue
                self.packets_from_robot += 1
                self._to_operators(packet)

    def _to_operators(self, packet: Packet) -> None:
        framed: bytes | None = None
        for op in self.operators:
            if op.wants(packet.command) and not op.closed:
                framed = framed or encode_packet(packet.command, packet.payload)
                op.write(framed)

    async def _heartbeats(self) -> None:
        number = self.datalist.number(CentralServerHeartbeat.DATA_NAME)
        if number is None:
            return
        while not self.robot.closed:
            self.robot.write(encode_packet(number, CentralServerHeartbeat().encode()))
            await asyncio.sleep(self.central.config.heartbeat_s)

    # -- operators ---------------------------------------------------------------------
    async def _accept(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        op = Operator(reader, writer, self.datalist)
        if len(self.operators) >= MAX_OPERATORS or not self.connected:
            op.abort()
            return
        self.operators.append(op)
        task = asyncio.current_task()
        if task is not None:
            self._tasks.add(task)
        try:
            await serve_operator(op, self._on_operator)
        except asyncio.CancelledError:
            pass
        finally:
            self._operator_gone(op)
            if task is not None:
                self._tasks.discard(task)

    def _on_operator(self, op: Operator, event: object) -> None:
        if isinstance(event, RequestOnce):
            op.asked_once.add(event.number)
            self.robot.write(encode_packet(event.number, event.args))
        elif isinstance(event, RequestReceived):
            op.subscriptions[event.number] = event.interval_ms
            self._ask_robot(event.number, event.args)
        elif isinstance(event, RequestStopped):
            op.subscriptions.pop(event.number, None)
            self._stop_if_unwanted(event.number)

    def _ask_robot(self, number: int, args: bytes) -> None:
        intervals = [op.subscriptions[number] for op in self.operators if number in op.subscriptions]
        positive = [i for i in intervals if i >= 0]
        interval = min(positive) if positive else -1
        self._forwarded[number] = interval
        self.robot.write(encode_packet(Request.COMMAND, Request(number, interval, args).encode()))

    def _stop_if_unwanted(self, number: int) -> None:
        if number in self._forwarded and not any(number in op.subscriptions for op in self.operators):
            del self._forwarded[number]
            self.robot.write(encode_packet(RequestStop.COMMAND, RequestStop(number).encode()))

    def _operator_gone(self, op: Operator) -> None:
        with contextlib.suppress(ValueError):
            self.operators.remove(op)
        for number in list(op.subscriptions):
            self._stop_if_unwanted(number)

    # -- lifetime ----------------------------------------------------------------------
    def close(self) -> None:
        """The robot went (or is replaced): close its port, its operators and its socket."""
        if self._server is not None:
            self._server.close()
            self._server = None
        for op in list(self.operators):
            op.conn.shutdown()
            op.flush()
            op.close()
        self.operators.clear()
        if not self.robot.closed:
            self.conn.shutdown()
            self.robot.write(self.conn.data_to_send())
            self.robot.close()
        self.central.forwarder_down(self)


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
        for fwd in list(self.forwarders):
            for op in fwd.operators:
                op.abort()
            fwd.robot.abort()
            fwd.close()
        for op in list(self.operators):
            op.abort()

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

    def ports_in_use(self) -> set[int]:
        return {f.port for f in self.forwarders if f.port}

    def robots(self) -> list[CentralEntry]:
        """The robots operators can reach now, in the order they came."""
        return [f.entry for f in self.forwarders if f.connected]

    # -- operators on the central port ----------------------------------------------------
    async def _accept_operator(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        op = Operator(reader, writer, OPERATOR_DATA)
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
                op.conn.send_data(event.name, ClientList(tuple(self.robots())).encode())
        elif isinstance(event, RequestStopped):
            op.subscriptions.pop(event.number, None)
        elif isinstance(event, RequestOnce) and event.name == ClientList.DATA_NAME:
            op.conn.send_data(event.name, ClientList(tuple(self.robots())).encode())

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
        if len(self.forwarders) >= self.config.max_robots:
            log.info("robot %s: already %d robots; closing it", peer.address, len(self.forwarders))
            peer.abort()
            return
        self._track()
        conn = ServerConnection(ROBOT_DATA, rng=KEY_RNG)
        peer.write(conn.data_to_send())
        name: str | None = None
        try:
            async with asyncio.timeout(self.config.login_timeout):
                while name is None:
                    data = await reader.read(READ_CHUNK)
                    if not data:
                        peer.abort()
                        return
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
                            return
                    peer.write(conn.data_to_send())
        except (TimeoutError, ConnectionError, OSError):
            peer.abort()
            return
        except asyncio.CancelledError:
            peer.abort()
            return
        conn.send_data(SwitchRequest.DATA_NAME)  # the empty acceptance; the socket turns round now
        peer.write(conn.data_to_send())
        await self._forward(peer, name or peer.address)

    async def _forward(self, peer: Peer, name: str) -> None:
        for old in [f for f in self.forwarders if f.name.lower() == name.lower()]:
            log.info("robot %r switched again; dropping its old connection", name)
            old.robot.abort()
            old.close()
        self.switches += 1
        forwarder = Forwarder(self, peer, name)
        self.forwarders.append(forwarder)
        try:
            await forwarder.run()
        except asyncio.CancelledError:
            forwarder.close()

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

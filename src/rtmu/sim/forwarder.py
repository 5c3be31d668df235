"""One robot behind the central server (ARIA's ``ArCentralForwarder``), and the peers it serves.

After the switch the forwarder logs in to the robot over the turned-round socket (no user, as ARIA's
does), asks ``centralHeartbeat`` every second and names itself ``CentralServer`` where the robot
takes ``identSetSelfIdentifier``. It then serves operators on a port of its own with the robot's data
under the robot's own numbers — all but those flagged ``DO_NOT_FORWARD`` or ``RETURN_COMPLEX`` or with
no return type it knows — and relays by ARIA's rules:

* a request-once of a ``RETURN_SINGLE`` / ``RETURN_UNTIL_EMPTY`` / video data queues the operator;
  the robot's next reply goes to the first in the queue (``RETURN_UNTIL_EMPTY``: until its empty
  packet), video replies to everyone queued; an operator gone meanwhile leaves a hole that eats its
  reply, so the queue stays in step with the robot; ``RETURN_VIDEO_OPTIM`` goes only to askers;
* anything else the robot sends goes to the operators subscribed to that data;
* one subscription upstream per data at the shortest interval any operator asked (−1 if all asked −1),
  each change also asked once so a newcomer gets data at once; REQUESTSTOP when the last one stops.

Bounded: operators per forwarder, queued requests per data, output queued per peer.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections import deque
from collections.abc import Awaitable, Callable
from enum import Enum, auto

from rtmu.protocol.auth import UserTable
from rtmu.protocol.client_connection import ClientConnection
from rtmu.protocol.commands import ServerCommand, is_control_command
from rtmu.protocol.datalist import DataEntry, DataList
from rtmu.protocol.errors import ProtocolError
from rtmu.protocol.events import (
    DataListReady,
    PeerShutdown,
    Rejected,
    RequestOnce,
    RequestReceived,
    RequestStopped,
)
from rtmu.protocol.packet import Packet, encode_packet
from rtmu.protocol.payloads.central import CentralEntry, CentralHeartbeat, CentralServerHeartbeat
from rtmu.protocol.payloads.control import Request, RequestStop
from rtmu.protocol.payloads.server import SelfIdentifier

from .peers import MAX_OPERATORS, READ_CHUNK, Operator, Peer, serve_operator

log = logging.getLogger("rtmu.sim.central")

MAX_WAITING = 256
"""Request-onces of one data waiting for the robot's replies; more are refused (not forwarded)."""
MAX_UPSTREAM_BACKLOG = 1024 * 1024
"""Requests queued for the robot beyond this: the operator sending more is dropped, not the robot."""
HEARTBEAT_MS = 1000
"""How often a forwarder asks the robot's ``centralHeartbeat`` (ARIA's 1 s)."""


class Return(Enum):
    """How a data's replies are routed (its ``RETURN_*`` flag)."""

    NONE = auto()
    SINGLE = auto()
    UNTIL_EMPTY = auto()
    VIDEO = auto()
    VIDEO_OPTIM = auto()


RETURN_FLAGS = {
    "RETURN_NONE": Return.NONE,
    "RETURN_SINGLE": Return.SINGLE,
    "RETURN_VIDEO": Return.VIDEO,
    "RETURN_VIDEO_OPTIM": Return.VIDEO_OPTIM,
    "RETURN_UNTIL_EMPTY": Return.UNTIL_EMPTY,
}
QUEUED = (Return.SINGLE, Return.UNTIL_EMPTY, Return.VIDEO, Return.VIDEO_OPTIM)


def return_type(entry: DataEntry) -> Return | None:
    """The routing of a data, or None when ARIA's forwarder does not forward it."""
    flags = entry.flag_set
    if "DO_NOT_FORWARD" in flags or "MAIN_SERVER_ONLY" in flags:
        return None
    for flag, kind in RETURN_FLAGS.items():  # ARIA tests them in this order
        if flag in flags:
            return kind
    return None  # RETURN_COMPLEX, or nothing it knows


Accept = Callable[[asyncio.StreamReader, asyncio.StreamWriter], Awaitable[None]]
Listen = Callable[[Accept], Awaitable[asyncio.base_events.Server]]
"""Open the forwarded port for an accept callback (the central server picks the port)."""


class Forwarder:
    """One switched robot: logged in to over its own socket, served to operators on its own port."""

    def __init__(
        self,
        robot: Peer,
        name: str,
        *,
        listen: Listen,
        on_up: Callable[[Forwarder], None],
        on_down: Callable[[Forwarder], None],
        users: UserTable | None = None,
        login_timeout: float = 10.0,
        heartbeat_s: float = 1.0,
        silence_timeout: float = 120.0,
    ) -> None:
        self.robot = robot
        self.name = name
        self._listen = listen
        self._on_up = on_up
        self._on_down = on_down
        self.users = users
        self.login_timeout = login_timeout
        self.heartbeat_s = heartbeat_s
        self.silence_timeout = silence_timeout
        """Seconds without a packet from the robot before it is dropped (ARIA's 2 min heartbeat timeout)."""
        self.port = 0
        self.connected = False
        self.closed = False
        self.conn = ClientConnection()
        self.robot_data = DataList()
        self.offered = DataList()
        """What operators see: the robot's forwardable data, under the robot's numbers."""
        self.returns: dict[int, Return] = {}
        self.operators: list[Operator] = []
        self.waiting: dict[int, deque[Operator | None]] = {}
        """Data number → operators whose request-once awaits the robot's reply (None: one gone)."""
        self._upstream: dict[int, int] = {}
        """Data number → the interval asked of the robot for it."""
        self._servers: list[asyncio.base_events.Server] = []
        self.packets_from_robot = 0

    @property
    def entry(self) -> CentralEntry:
        return CentralEntry("", self.port, self.name, "", self.robot.address)

    # -- lifetime ----------------------------------------------------------------------------
    async def run(self) -> None:
        """Log in to the robot, open the forwarded port, then relay until the robot goes."""
        try:
            async with asyncio.timeout(self.login_timeout):
                await self._login()
            server = await self._listen(self._accept)
            self._servers.append(server)
            self.port = int(server.sockets[0].getsockname()[1])
        except (TimeoutError, ConnectionError, OSError, ProtocolError) as exc:
            log.info("robot %r: cannot forward it: %s", self.name, exc or type(exc).__name__)
            self.close()
            return
        self._greet_robot()
        self.connected = True
        self._on_up(self)
        heartbeat = asyncio.get_running_loop().create_task(self._heartbeats())
        try:
            await self._relay()
        finally:
            heartbeat.cancel()
            self.close()

    def close(self) -> None:
        """The robot went (or is replaced): close its port, its operators and its socket."""
        if self.closed:
            return
        self.closed = True
        for server in self._servers:
            server.close()
        self._servers.clear()
        for op in list(self.operators):
            op.goodbye()
        self.operators.clear()
        if not self.robot.closed:
            self.conn.shutdown()
            self.robot.write(self.conn.data_to_send())
            self.robot.close()
        self._on_down(self)

    async def _login(self) -> None:
        while True:
            data = await self.robot.reader.read(READ_CHUNK)
            if not data:
                raise ConnectionError("the robot closed the switched connection during login")
            events = self.conn.receive_data(data)  # a malformed introduction raises ProtocolError
            self.robot.write(self.conn.data_to_send())
            for event in events:
                if isinstance(event, Rejected):
                    raise ConnectionError(f"the robot refused our login (reason {event.reason})")
                if isinstance(event, PeerShutdown):
                    raise ConnectionError("the robot shut the connection down during login")
                if isinstance(event, DataListReady):
                    self._offer(event.datalist)
                    return

    def _offer(self, robot_data: DataList) -> None:
        self.robot_data = robot_data
        for entry in robot_data:
            kind = return_type(entry)
            if kind is not None:
                self.returns[entry.number] = kind
                self.offered.add(entry)

    def _greet_robot(self) -> None:
        data = self.robot_data
        if CentralHeartbeat.DATA_NAME in data:
            self.conn.request(CentralHeartbeat.DATA_NAME, HEARTBEAT_MS)
        if SelfIdentifier.DATA_NAME in data:
            self.conn.send(SelfIdentifier("CentralServer"))
        self.robot.write(self.conn.data_to_send())

    async def _heartbeats(self) -> None:
        number = self.robot_data.number(CentralServerHeartbeat.DATA_NAME)
        if number is None:
            return
        while not self.robot.closed:
            self.robot.write(encode_packet(number, CentralServerHeartbeat().encode()))
            await asyncio.sleep(self.heartbeat_s)

    # -- the robot's packets -----------------------------------------------------------------
    async def _relay(self) -> None:
        decoder = self.conn.decoder
        while not self.robot.closed:
            try:
                async with asyncio.timeout(self.silence_timeout):
                    data = await self.robot.reader.read(READ_CHUNK)
            except TimeoutError:
                # It answers centralHeartbeat every second: a robot this quiet has lost its link.
                log.info("robot %r: nothing for %g s; dropping it", self.name, self.silence_timeout)
                self.robot.abort()
                return
            except (ConnectionError, OSError):
                return
            if not data:
                return
            for packet in decoder.feed(data):
                if packet.command == ServerCommand.SHUTDOWN:
                    return
                if not is_control_command(packet.command):
                    self.packets_from_robot += 1
                    self._route(packet)

    def _route(self, packet: Packet) -> None:
        number = packet.command
        kind = self.returns.get(number)
        if kind is None:
            return  # not offered (the heartbeat's answers, data we do not forward)
        queue = self.waiting.get(number)
        framed = encode_packet(number, packet.payload)
        if kind in (Return.SINGLE, Return.UNTIL_EMPTY) and queue:
            op = queue[0]
            if op is not None:
                op.write(framed)
            if kind is Return.SINGLE or not packet.payload:
                queue.popleft()
            return
        if kind in (Return.VIDEO, Return.VIDEO_OPTIM):
            while queue:
                op = queue.popleft()
                if op is not None and (kind is Return.VIDEO_OPTIM or number not in op.subscriptions):
                    op.write(framed)
            if kind is Return.VIDEO_OPTIM:
                return  # only ever to those who asked
        for op in self.operators:
            if number in op.subscriptions:
                op.write(framed)

    # -- operators ---------------------------------------------------------------------------
    async def _accept(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        op = Operator(reader, writer, self.offered, self.users)
        if len(self.operators) >= MAX_OPERATORS or self.closed:
            op.abort()
            return
        self.operators.append(op)
        try:
            await serve_operator(op, self._on_operator)
        except asyncio.CancelledError:
            pass
        finally:
            self._operator_gone(op)

    def _on_operator(self, op: Operator, event: object) -> None:
        if self._robot_backlog() > MAX_UPSTREAM_BACKLOG:
            # The robot is not taking requests as fast as they come: whoever keeps sending more is
            # dropped, before the robot's own link (which every operator shares) overflows.
            log.info(
                "robot %r: %d bytes of requests queued; dropping operator %s",
                self.name,
                MAX_UPSTREAM_BACKLOG,
                op.address,
            )
            op.abort()
            return
        if isinstance(event, RequestOnce):
            self._ask_once(op, event.number, event.args)
        elif isinstance(event, RequestReceived):
            op.subscriptions[event.number] = event.interval_ms
            self._resubscribe(event.number, event.args, asked=True)
        elif isinstance(event, RequestStopped):
            op.subscriptions.pop(event.number, None)
            self._resubscribe(event.number, b"")

    def _robot_backlog(self) -> int:
        transport = self.robot.writer.transport
        return 0 if transport is None or transport.is_closing() else transport.get_write_buffer_size()

    def _ask_once(self, op: Operator | None, number: int, args: bytes) -> None:
        if self.returns.get(number) in QUEUED:
            queue = self.waiting.setdefault(number, deque())
            if len(queue) >= MAX_WAITING:
                log.info(
                    "robot %r: %d requests of data %d waiting; refusing one", self.name, len(queue), number
                )
                return
            queue.append(op)
        self.robot.write(encode_packet(number, args))

    def _resubscribe(self, number: int, args: bytes, *, asked: bool = False) -> None:
        """Ask the robot for ``number`` at the shortest interval any operator wants, or stop it."""
        intervals = [op.subscriptions[number] for op in self.operators if number in op.subscriptions]
        if not intervals:
            if self._upstream.pop(number, None) is not None:
                self.robot.write(encode_packet(RequestStop.COMMAND, RequestStop(number).encode()))
            return
        positive = [i for i in intervals if i >= 0]
        interval = min(positive) if positive else -1
        if self._upstream.get(number) == interval and not asked:
            return
        self._upstream[number] = interval
        self.robot.write(encode_packet(Request.COMMAND, Request(number, interval, args).encode()))
        if self.returns.get(number) not in (Return.VIDEO, Return.VIDEO_OPTIM):
            # ARIA asks once too, unqueued, so whoever joined gets data now (to the subscribers).
            self.robot.write(encode_packet(number, args))

    def _operator_gone(self, op: Operator) -> None:
        with contextlib.suppress(ValueError):
            self.operators.remove(op)
        for queue in self.waiting.values():
            for i, waiting in enumerate(queue):
                if waiting is op:
                    queue[i] = None  # keep the queue in step with the replies still coming
        for number in list(op.subscriptions):
            self._resubscribe(number, b"")

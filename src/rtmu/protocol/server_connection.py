"""The server end of an ArNetworking connection, sans-I/O (protocol §2.3–2.7, §3).

It introduces itself at once, validates the client's INTRODUCTION (user file
and digest when configured), sends CONNECTED and the list packets, and then
turns packets into request events. The caller keeps subscriptions and timers;
this class only knows the wire.
"""

from __future__ import annotations

import random
from enum import Enum, auto

from .auth import User, UserTable, make_password_key
from .commands import VERSION_TAG, ClientCommand, RejectReason, ServerCommand, is_control_command
from .datalist import DataList
from .decoder import PacketDecoder
from .errors import ProtocolError
from .events import (
    ClientIntroduced,
    Event,
    Ignored,
    LoginRefused,
    PeerShutdown,
    RequestOnce,
    RequestReceived,
    RequestStopped,
    TcpOnlyRequested,
)
from .packet import Packet, encode_packet
from .payloads.control import ClientIntroduction, Rejected, Request, RequestStop, ServerIntroduction


class ServerState(Enum):
    SENT_INTRODUCTION = auto()
    CONNECTED = auto()
    CLOSING = auto()
    CLOSED = auto()


class ServerConnection:
    def __init__(
        self,
        datalist: DataList,
        users: UserTable | None = None,
        *,
        server_key: str = "",
        udp_port: int = 0,
        rng: random.Random | None = None,
        protocol_version: str = "",
    ) -> None:
        self._full_datalist = datalist
        self.datalist = datalist
        self.users = users
        self.server_key = server_key
        self.user: User | None = None
        self.tcp_only = False
        self.subscriptions: dict[int, int] = {}
        self.malformed_packets = 0
        """Control packets that did not decode (a refused login, an ignored REQUEST): for logs and tests."""
        self.state = ServerState.SENT_INTRODUCTION
        self.decoder = PacketDecoder()
        rng = rng or random.SystemRandom()
        self.auth_key = rng.randrange(1 << 31)
        self.intro_key = rng.randrange(1 << 31)
        self.password_key = make_password_key(rng)  # type: ignore[arg-type]
        self._out = bytearray()
        # ARIA advertises the protocol string it enforces (§2.4 field 6).
        intro = ServerIntroduction(
            VERSION_TAG, udp_port, self.auth_key, self.intro_key, self.password_key, protocol_version
        )
        self._send(ServerCommand.INTRODUCTION, intro.encode())

    # -- output ---------------------------------------------------------
    def data_to_send(self) -> bytes:
        out = bytes(self._out)
        self._out.clear()
        return out

    def _send(self, command: int, payload: bytes = b"") -> None:
        self._out += encode_packet(command, payload)

    def send_data(self, name: str, payload: bytes = b"") -> None:
        """Send a reply or broadcast for ``name`` (a reply carries the data's own number)."""
        number = self.datalist.number(name)
        if number is None or self.state is not ServerState.CONNECTED:
            return
        self._send(number, payload)

    def send_raw(self, data: bytes) -> None:
        """Already-framed bytes (a cached map stream); for the simulator's hot paths."""
        self._out += data

    def shutdown(self) -> None:
        if self.state is ServerState.CONNECTED:
            self._send(ServerCommand.SHUTDOWN)
        self.state = ServerState.CLOSED

    def reject(self, reason: RejectReason, text: str = "") -> LoginRefused:
        self._send(ServerCommand.REJECTED, Rejected(int(reason), text).encode())
        self.state = ServerState.CLOSING
        return LoginRefused(int(reason), text)

    # -- input ------------------------------------------------------------
    def receive_data(self, data: bytes) -> list[Event]:
        events: list[Event] = []
        for packet in self.decoder.feed(data):
            if self.state in (ServerState.CLOSING, ServerState.CLOSED):
                break
            events.extend(self._handle(packet))
        return events

    def _handle(self, packet: Packet) -> list[Event]:
        cmd = packet.command
        if cmd == ClientCommand.TCP_ONLY or (
            cmd == ClientCommand.UDP_INTRODUCTION and self.state is ServerState.CONNECTED
        ):
            self.tcp_only = True
            return [TcpOnlyRequested()]
        if cmd == ClientCommand.SHUTDOWN:
            self.state = ServerState.CLOSED
            return [PeerShutdown()]
        if self.state is ServerState.SENT_INTRODUCTION:
            if cmd != ClientCommand.INTRODUCTION:
                return [Ignored(cmd, "before the client's introduction")]
            return [self._on_introduction(packet)]
        if cmd == ClientCommand.REQUEST:
            return self._on_request(packet)
        if cmd == ClientCommand.REQUESTSTOP:
            return self._on_request_stop(packet)
        if is_control_command(cmd):
            return [Ignored(cmd, "control command not handled by a server")]
        entry = self.datalist.entry(cmd)
        if entry is None:
            return [Ignored(cmd, "unknown data number")]
        return [RequestOnce(cmd, entry.name, packet.payload)]

    def _on_introduction(self, packet: Packet) -> ClientIntroduced | LoginRefused:
        try:
            intro: ClientIntroduction | None = ClientIntroduction.decode(packet.payload)
        except ProtocolError:
            self.malformed_packets += 1
            intro = None
        refused = self._refusal(intro)
        if refused is not None:
            return refused
        assert intro is not None  # _refusal refuses a malformed introduction
        self.state = ServerState.CONNECTED
        self._send(ServerCommand.CONNECTED)
        for list_packet in self.datalist.list_packets():
            self._send(list_packet.command, list_packet.payload)
        return ClientIntroduced(intro.user, intro.udp_port, intro.protocol_version, intro.client_type)

    def _refusal(self, intro: ClientIntroduction | None) -> LoginRefused | None:
        """Check a login (None: its INTRODUCTION did not decode); refuse it, or remember the user.

        A subclass puts ARIA's other checks (central server, version, type) before these, in ARIA's order.
        """
        if intro is None:
            return self.reject(RejectReason.BAD_USER_OR_PASSWORD)
        if self.users is not None:
            found = self.users.check(intro.user, intro.password_digest, self.password_key, self.server_key)
            if found is None:
                return self.reject(RejectReason.BAD_USER_OR_PASSWORD)
            self.user = found
            self.datalist = self._full_datalist.visible_to(found.groups)
        return None

    def _on_request(self, packet: Packet) -> list[Event]:
        try:
            request = Request.decode(packet.payload)
        except ProtocolError as exc:
            self.malformed_packets += 1
            return [Ignored(packet.command, str(exc))]
        number = request.number
        entry = self.datalist.entry(number)
        if entry is None:
            return [Ignored(packet.command, f"REQUEST for unknown or forbidden data {number}")]
        new = number not in self.subscriptions
        self.subscriptions[number] = request.interval_ms
        return [RequestReceived(number, entry.name, request.interval_ms, request.args, new)]

    def _on_request_stop(self, packet: Packet) -> list[Event]:
        try:
            number = RequestStop.decode(packet.payload).number
        except ProtocolError as exc:
            self.malformed_packets += 1
            return [Ignored(packet.command, str(exc))]
        if number not in self.subscriptions:
            return [Ignored(packet.command, f"REQUESTSTOP for data {number} that is not subscribed")]
        del self.subscriptions[number]
        return [RequestStopped(number, self.datalist.name(number) or "")]

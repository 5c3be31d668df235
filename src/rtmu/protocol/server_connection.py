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
from .commands import ClientCommand, RejectReason, ServerCommand, is_control_command
from .datalist import DataList
from .decoder import PacketDecoder
from .errors import FieldUnderrun
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
from .fields import FieldReader, FieldWriter
from .packet import Packet, encode_packet

VERSION_TAG = "alpha"


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
        self.state = ServerState.SENT_INTRODUCTION
        self.decoder = PacketDecoder()
        rng = rng or random.SystemRandom()
        self.auth_key = rng.randrange(1 << 31)
        self.intro_key = rng.randrange(1 << 31)
        self.password_key = make_password_key(rng)  # type: ignore[arg-type]
        self._out = bytearray()
        intro = (
            FieldWriter()
            .string(VERSION_TAG)
            .ubyte2(udp_port)
            .ubyte4(self.auth_key)
            .ubyte4(self.intro_key)
            .string(self.password_key)
            .string(protocol_version)  # ARIA advertises the string it enforces (§2.4 field 6)
            .bytes()
        )
        self._send(ServerCommand.INTRODUCTION, intro)

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
        self._send(ServerCommand.REJECTED, FieldWriter().byte2(int(reason)).string(text).bytes())
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
        r = FieldReader(packet.payload)
        try:
            udp_port = r.ubyte2("client UDP port")
            user = r.string("user name")
            digest = r.raw(16, "password digest")
            version = r.string("protocol version", default="")
            client_type = r.byte("client type", default=0)
        except FieldUnderrun:
            return self.reject(RejectReason.BAD_USER_OR_PASSWORD)
        if self.users is not None:
            found = self.users.check(user, digest, self.password_key, self.server_key)
            if found is None:
                return self.reject(RejectReason.BAD_USER_OR_PASSWORD)
            self.user = found
            self.datalist = self._full_datalist.visible_to(found.groups)
        self.state = ServerState.CONNECTED
        self._send(ServerCommand.CONNECTED)
        for list_packet in self.datalist.list_packets():
            self._send(list_packet.command, list_packet.payload)
        return ClientIntroduced(user, udp_port, version, client_type)

    def _on_request(self, packet: Packet) -> list[Event]:
        r = FieldReader(packet.payload)
        try:
            number = r.ubyte2("data number")
            interval = r.byte4("interval")
        except FieldUnderrun as exc:
            return [Ignored(packet.command, str(exc))]
        entry = self.datalist.entry(number)
        if entry is None:
            return [Ignored(packet.command, f"REQUEST for unknown or forbidden data {number}")]
        new = number not in self.subscriptions
        self.subscriptions[number] = interval
        return [RequestReceived(number, entry.name, interval, r.rest(), new)]

    def _on_request_stop(self, packet: Packet) -> list[Event]:
        number = FieldReader(packet.payload).ubyte2("data number", default=-1)
        if number not in self.subscriptions:
            return [Ignored(packet.command, f"REQUESTSTOP for data {number} that is not subscribed")]
        del self.subscriptions[number]
        return [RequestStopped(number, self.datalist.name(number) or "")]

"""The client end of an ArNetworking connection, sans-I/O (protocol §2.3–2.14, §3).

Feed received bytes to :meth:`ClientConnection.receive_data`; it returns
events. Calls such as :meth:`request` queue bytes; :meth:`data_to_send` hands
them over for the caller's socket. No sockets, no asyncio, no clocks here.

The client is TCP-only: it declares UDP port 0 and sends TCP_ONLY right after
its INTRODUCTION (what ``ArClientBase`` does with a server without UDP), so
every reply arrives on the one socket.

Requests sent with :meth:`ClientConnection.request_reply` are *tracked*: the
connection's :class:`~rtmu.protocol.replies.ReplyTracker` owns each one until
its reply ends, and ``receive_data`` reports its packets as ``ReplyPacket`` and
its end as ``ReplyComplete``/``ReplyFailed`` (see :mod:`.replies`). Packets no
tracked request claims come out as ``DataReceived``. A typed
:class:`~rtmu.protocol.payloads.Payload` names its own data: ``send(RatioDrive(…))``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict
from enum import Enum, auto

from .auth import password_digest
from .commands import (
    FIRST_DATA_NUMBER,
    ClientCommand,
    ClientType,
    ServerCommand,
    is_control_command,
)
from .datalist import DataList
from .decoder import PacketDecoder
from .errors import ProtocolError
from .events import (
    Connected,
    DataListReady,
    Event,
    Ignored,
    PeerShutdown,
    Rejected,
    ReplyId,
    ServerIntroduction,
)
from .fields import FieldWriter
from .packet import Packet, encode_packet
from .payloads import control
from .payloads.base import NameMatch, Payload
from .replies import MAX_REPLY_BYTES, MAX_REPLY_PACKETS, ReplyTracker, end_rule


class ClientState(Enum):
    WAITING_INTRODUCTION = auto()
    EXCHANGED_INTROS = auto()
    WAITING_LIST = auto()
    CONNECTED = auto()
    REJECTED = auto()
    CLOSED = auto()


class UnknownData(ProtocolError):
    """The server's data list has no such name."""


class ClientConnection:
    def __init__(
        self,
        user: str = "",
        password: str = "",
        *,
        server_key: str = "",
        protocol_version: str | None = None,
        client_type: ClientType = ClientType.UNSPECIFIED,
    ) -> None:
        self.user = user
        self._password = password
        self.server_key = server_key
        self.protocol_version = protocol_version
        """What we answer; None: the string the server advertises (what an enforcing server wants)."""
        self.sent_protocol_version: str | None = None
        self.client_type = client_type
        self.state = ClientState.WAITING_INTRODUCTION
        self.datalist = DataList()
        self.decoder = PacketDecoder()
        self.introduction: ServerIntroduction | None = None
        self.replies = ReplyTracker()
        """The tracked requests waiting for replies (see :meth:`request_reply`)."""
        self._out = bytearray()

    # -- output -------------------------------------------------------------
    def data_to_send(self) -> bytes:
        out = bytes(self._out)
        self._out.clear()
        return out

    def _send(self, command: int, payload: bytes = b"") -> None:
        self._out += encode_packet(command, payload)

    def number_of(self, name: str) -> int:
        number = self.datalist.number(name)
        if number is None:
            raise UnknownData(f"the server offers no data named {name!r}")
        return number

    def request(self, name: str, interval_ms: int, args: bytes = b"") -> None:
        """Subscribe: the server answers now and then every ``interval_ms`` (−1: broadcasts only)."""
        self._require_connected()
        payload = FieldWriter().ubyte2(self.number_of(name)).byte4(interval_ms).bytes() + args
        self._send(ClientCommand.REQUEST, payload)

    def request_stop(self, name: str) -> None:
        self._require_connected()
        self._send(ClientCommand.REQUESTSTOP, FieldWriter().ubyte2(self.number_of(name)).bytes())

    def request_once(self, what: str | Payload, args: bytes = b"") -> None:
        """Run data ``what`` once: a packet whose command is the data number, payload the arguments.

        ``what`` is a data name (``args`` its encoded arguments) or a typed payload that names its data.
        The reply, if any, is not tracked: it arrives as ``DataReceived`` (see :meth:`request_reply`).
        """
        name, args = named(what, args)
        self._require_connected()
        self._send(self.number_of(name), args)

    def send(self, payload: Payload, *, name: str | None = None) -> None:
        """Send a typed command; its type picks the data (``name`` only for a family: ``setCameraRel…``)."""
        self.request_once(name or payload_name(payload), payload.encode())

    def request_reply(
        self,
        what: str | Payload,
        args: bytes = b"",
        *,
        now: float,
        expect: int | None = None,
        until: Callable[[bytes], bool] | None = None,
        streaming: bool = False,
        max_packets: int = MAX_REPLY_PACKETS,
        max_bytes: int = MAX_REPLY_BYTES,
    ) -> ReplyId | None:
        """Run ``what`` once and track its reply until it ends; None when the data has no reply.

        ``expect=n``: the reply is n packets; ``until(payload) -> bool``: the caller's own end
        test. ``streaming``: packets are handed out in ``ReplyPacket`` events and only those
        not yet :meth:`reply_taken` count against the bounds. Raises ``TooManyPending``
        (nothing sent) when too many requests of this data already wait.
        """
        name, args = named(what, args)
        self._require_connected()
        number = self.number_of(name)
        entry = self.datalist.entry(number)
        flags = entry.flag_set if entry else frozenset()
        rule = end_rule(flags, name, expect, until)
        if rule is None:
            self._send(number, args)
            return None
        fallback = end_rule(flags, name, expect) or rule
        pending = self.replies.expect(
            number, name, rule, fallback, now=now, streaming=streaming,
            max_packets=max_packets, max_bytes=max_bytes,
        )  # fmt: skip
        self._send(number, args)
        return pending.id

    def abandon_reply(self, reply: ReplyId, now: float) -> None:
        """Its waiter gave up: the rest of the reply is swallowed, never taken for a later request's."""
        self.replies.abandon(reply, now)

    def reply_taken(self, reply: ReplyId, payload: bytes) -> None:
        """A streamed reply's reader took ``payload``: it no longer counts against the bounds."""
        self.replies.taken(reply, payload)

    def shutdown(self) -> None:
        """Say goodbye; the caller then closes the socket."""
        if self.state not in (ClientState.CLOSED, ClientState.REJECTED):
            self._send(ClientCommand.SHUTDOWN)
        self.state = ClientState.CLOSED

    def _require_connected(self) -> None:
        if self.state is not ClientState.CONNECTED:
            raise ProtocolError(f"not connected (state {self.state.name})")

    # -- input --------------------------------------------------------------
    def receive_data(self, data: bytes, now: float | None = None) -> list[Event]:
        """Bytes from the server → events; ``now`` dates the packets for the reply tracker's expiry."""
        if now is not None:
            self.replies.now = now
        events: list[Event] = []
        feed, name_of, extend = self.replies.feed, self.datalist.names.get, events.extend
        connected = self.state is ClientState.CONNECTED
        for packet in self.decoder.feed(data):
            cmd, payload = packet
            if connected and cmd >= FIRST_DATA_NUMBER:  # the data: most packets
                extend(feed(cmd, name_of(cmd), payload))
            else:
                extend(self._handle(packet))
                connected = self.state is ClientState.CONNECTED
        return events

    def _handle(self, packet: Packet) -> list[Event]:
        cmd = packet.command
        state = self.state
        if state in (ClientState.CLOSED, ClientState.REJECTED):
            return [Ignored(cmd, f"connection is {state.name.lower()}")]
        if cmd == ServerCommand.SHUTDOWN:
            self.state = ClientState.CLOSED
            return [PeerShutdown()]
        if state is ClientState.WAITING_INTRODUCTION:
            if cmd != ServerCommand.INTRODUCTION:
                return [Ignored(cmd, "waiting for the server's introduction")]
            return [self._on_introduction(packet)]
        if cmd in (ServerCommand.TCP_ONLY, ServerCommand.UDP_CONFIRMATION, ServerCommand.UDP_INTRODUCTION):
            return [Ignored(cmd, "TCP-only client: UDP bookkeeping is not needed")]
        if state is ClientState.EXCHANGED_INTROS:
            if cmd == ServerCommand.CONNECTED:
                self.state = ClientState.WAITING_LIST
                return [Connected()]
            if cmd == ServerCommand.REJECTED:
                return [self._on_rejected(packet)]
            return [Ignored(cmd, "waiting for CONNECTED or REJECTED")]
        if cmd == ServerCommand.REJECTED and state is ClientState.WAITING_LIST:
            return [self._on_rejected(packet)]
        if is_control_command(cmd):
            if self.datalist.absorb(packet):
                if self.state is ClientState.WAITING_LIST and self.datalist.complete:
                    self.state = ClientState.CONNECTED
                    return [DataListReady(self.datalist)]
                return []
            return [Ignored(cmd, "unexpected control command")]
        if state is not ClientState.CONNECTED:
            return [Ignored(cmd, "data before the data list was complete")]
        return self.replies.feed(cmd, self.datalist.name(cmd), packet.payload)

    def _on_introduction(self, packet: Packet) -> ServerIntroduction:
        try:
            theirs = control.ServerIntroduction.decode(packet.payload)
        except ProtocolError as exc:
            raise ProtocolError(f"malformed server introduction: {exc}") from exc
        intro = ServerIntroduction(**asdict(theirs))
        self.introduction = intro
        digest = password_digest(self._password, intro.password_key, self.server_key)
        self._password = ""  # not kept longer than needed
        answer = intro.protocol_version if self.protocol_version is None else self.protocol_version
        self.sent_protocol_version = answer
        ours = control.ClientIntroduction(0, self.user, digest, answer, int(self.client_type))
        self._send(ClientCommand.INTRODUCTION, ours.encode())
        self._send(ClientCommand.TCP_ONLY)
        self.state = ClientState.EXCHANGED_INTROS
        return intro

    def _on_rejected(self, packet: Packet) -> Rejected:
        refusal = control.Rejected.decode(packet.payload)  # a missing field reads as 0 or "", never fails
        self.state = ClientState.REJECTED
        return Rejected(refusal.reason, refusal.text, refusal.explanation)

    def wanted_protocol(self) -> str | None:
        """The protocol string the server advertised (None before its introduction)."""
        return None if self.introduction is None else self.introduction.protocol_version


def payload_name(payload: Payload) -> str:
    """The data a typed payload is sent as; a family type (camera, range device) cannot say which."""
    cls = type(payload)
    if cls.NAME_MATCH is not NameMatch.EXACT:
        raise ProtocolError(f"{cls.__name__} is sent under several data names: say which")
    return cls.DATA_NAME


def named(what: str | Payload, args: bytes = b"") -> tuple[str, bytes]:
    """(data name, argument bytes) from a name and its bytes, or from a typed payload alone."""
    if isinstance(what, Payload):
        if args:
            raise TypeError("a typed payload carries its own arguments")
        return payload_name(what), what.encode()
    return what, args

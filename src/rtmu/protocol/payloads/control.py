"""Control packets (protocol §2.2–2.6, §3.2–3.3): the handshake, REQUEST and REQUESTSTOP.

Control commands are numbered below 256 and mean different things in each
direction, so they are found by (command, side) rather than by data name:
``Side.ARGS`` is what a client sends, ``Side.REPLY`` what a server sends, as
for data. The client, the server codec, the simulator and ``rtmu decode`` all
read and write these packets through the classes here.

A "request once" has no envelope (its command is the data number, its
payload the data's own ``ARGS`` type), and the list packets are read and
built by :class:`~rtmu.protocol.datalist.DataList`; neither appears here.

Optional trailing fields are read as ARIA reads them (a missing string is
``""``, a missing number 0) and always written, as ARIA 2.9.1 writes them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Self, TypeVar

from ..commands import ClientCommand, ClientType, ServerCommand, describe_reject
from ..fields import FieldReader, FieldWriter
from .base import EmptyPayload, Payload, Side

DIGEST_LENGTH = 16
"""The MD5 password digest travels as 16 raw bytes, with no length and no terminator (§2.5)."""


class ControlPayload(Payload):
    """A control packet's payload: found by its command number and the side that sends it."""

    __slots__ = ()

    DATA_NAME = ""  # control packets have numbers, not data names
    COMMAND: ClassVar[int]


_CONTROL: dict[tuple[int, Side], type[ControlPayload]] = {}
C = TypeVar("C", bound=type[ControlPayload])


def control(cls: C) -> C:
    """Class decorator: make ``cls`` the payload type of its command from its side."""
    key = (int(cls.COMMAND), cls.SIDE)
    if key in _CONTROL:
        raise RuntimeError(f"two control payload types for {key}")
    _CONTROL[key] = cls
    return cls


def control_type(command: int, side: Side) -> type[ControlPayload] | None:
    """The payload type of control ``command`` sent by ``side`` (ARGS: client), or None if unknown."""
    return _CONTROL.get((command, side))


def control_types() -> dict[tuple[int, Side], type[ControlPayload]]:
    return dict(_CONTROL)


# -- server → client ---------------------------------------------------------------


@control
@dataclass(frozen=True, slots=True)
class ServerIntroduction(ControlPayload):
    """The server's INTRODUCTION, sent on accept: its keys for this connection (§2.4).

    It is also the event the client codec reports: the fields are what a caller needs.
    """

    COMMAND = ServerCommand.INTRODUCTION
    SIDE = Side.REPLY

    version_tag: str
    """Always ``"alpha"``."""
    udp_port: int
    """0: the server has no UDP."""
    auth_key: int
    intro_key: int
    password_key: str
    """Mixed into the password digest, so a recorded login cannot be replayed."""
    protocol_version: str = ""
    """The version the server enforces; ``""`` when it enforces none (or, older servers, omits it)."""

    def encode(self) -> bytes:
        return (
            FieldWriter()
            .string(self.version_tag)
            .ubyte2(self.udp_port)
            .ubyte4(self.auth_key)
            .ubyte4(self.intro_key)
            .string(self.password_key)
            .string(self.protocol_version)
            .bytes()
        )

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(
            version_tag=r.string("version tag"),
            udp_port=r.ubyte2("server UDP port"),
            auth_key=r.ubyte4("auth key"),
            intro_key=r.ubyte4("intro key"),
            password_key=r.string("password key"),
            protocol_version=r.string("protocol version", default=""),
        )


@control
@dataclass(frozen=True, slots=True)
class Rejected(ControlPayload):
    """REJECTED: the server refuses the login (§2.6). A missing field reads as 0 or "", as in ARIA."""

    COMMAND = ServerCommand.REJECTED
    SIDE = Side.REPLY

    reason: int = 0
    """A :class:`~rtmu.protocol.commands.RejectReason`, kept as a number: a server may send others."""
    text: str = ""

    @property
    def explanation(self) -> str:
        """A sentence for operators and logs."""
        return describe_reject(self.reason, self.text)

    def encode(self) -> bytes:
        return FieldWriter().byte2(self.reason).string(self.text).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(r.byte2("reason", default=0), r.string("text", default=""))


@control
@dataclass(frozen=True, slots=True)
class ServerUdpIntroduction(ControlPayload):
    """The server's UDP_INTRODUCTION, sent by UDP: proves the datagrams come from it (§2.9).

    ARIA writes the key as a signed ``byte4``; it is read unsigned, as in the INTRODUCTION,
    so the two compare equal (keys are below 2^31 either way).
    """

    COMMAND = ServerCommand.UDP_INTRODUCTION
    SIDE = Side.REPLY

    intro_key: int

    def encode(self) -> bytes:
        return FieldWriter().ubyte4(self.intro_key).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(FieldReader(data).ubyte4("intro key"))


@control
@dataclass(frozen=True, slots=True)
class ServerShutdown(EmptyPayload, ControlPayload):
    """SHUTDOWN from the server: it is closing."""

    COMMAND = ServerCommand.SHUTDOWN
    SIDE = Side.REPLY


@control
@dataclass(frozen=True, slots=True)
class Connected(EmptyPayload, ControlPayload):
    """CONNECTED: the login was accepted; the list packets follow."""

    COMMAND = ServerCommand.CONNECTED
    SIDE = Side.REPLY


@control
@dataclass(frozen=True, slots=True)
class ServerUdpConfirmation(EmptyPayload, ControlPayload):
    """UDP_CONFIRMATION from the server (over TCP): the client's UDP datagram arrived."""

    COMMAND = ServerCommand.UDP_CONFIRMATION
    SIDE = Side.REPLY


@control
@dataclass(frozen=True, slots=True)
class ServerTcpOnly(EmptyPayload, ControlPayload):
    """TCP_ONLY from the server: it will send everything over TCP from now on."""

    COMMAND = ServerCommand.TCP_ONLY
    SIDE = Side.REPLY


# -- client → server ---------------------------------------------------------------


@control
@dataclass(frozen=True, slots=True)
class ClientIntroduction(ControlPayload):
    """The client's INTRODUCTION: who logs in, and with what (§2.5)."""

    COMMAND = ClientCommand.INTRODUCTION
    SIDE = Side.ARGS

    udp_port: int
    """Where the client wants UDP; 0 for a TCP-only client."""
    user: str
    password_digest: bytes
    """MD5 over server key, the server's password key and the password (:mod:`rtmu.protocol.auth`)."""
    protocol_version: str = ""
    client_type: int = int(ClientType.UNSPECIFIED)
    """A :class:`~rtmu.protocol.commands.ClientType`, kept as a number: a client may send others."""

    def encode(self) -> bytes:
        if len(self.password_digest) != DIGEST_LENGTH:
            raise ValueError(f"a password digest is {DIGEST_LENGTH} bytes, not {len(self.password_digest)}")
        return (
            FieldWriter()
            .ubyte2(self.udp_port)
            .string(self.user)
            .raw(self.password_digest)
            .string(self.protocol_version)
            .byte(self.client_type)
            .bytes()
        )

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(
            udp_port=r.ubyte2("client UDP port"),
            user=r.string("user name"),
            password_digest=r.raw(DIGEST_LENGTH, "password digest"),
            protocol_version=r.string("protocol version", default=""),
            client_type=r.byte("client type", default=int(ClientType.UNSPECIFIED)),
        )


@control
@dataclass(frozen=True, slots=True)
class Request(ControlPayload):
    """REQUEST: subscribe to a data, answered now and then every ``interval_ms`` (§3.2).

    ``interval_ms`` −1 means broadcasts only; ``args`` are the data's own arguments, kept as
    bytes (their type depends on the data) and stored by the server for every periodic call.
    """

    COMMAND = ClientCommand.REQUEST
    SIDE = Side.ARGS

    number: int
    """The data number, from the server's list."""
    interval_ms: int
    args: bytes = b""

    def encode(self) -> bytes:
        return FieldWriter().ubyte2(self.number).byte4(self.interval_ms).raw(self.args).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        r = FieldReader(data)
        return cls(r.ubyte2("data number"), r.byte4("interval"), r.rest())


@control
@dataclass(frozen=True, slots=True)
class RequestStop(ControlPayload):
    """REQUESTSTOP: end the subscription to one data (§3.3)."""

    COMMAND = ClientCommand.REQUESTSTOP
    SIDE = Side.ARGS

    number: int

    def encode(self) -> bytes:
        return FieldWriter().ubyte2(self.number).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(FieldReader(data).ubyte2("data number"))


@control
@dataclass(frozen=True, slots=True)
class ClientUdpIntroduction(ControlPayload):
    """The client's UDP_INTRODUCTION: by UDP it names its connection; over TCP it means TCP only (§2.9)."""

    COMMAND = ClientCommand.UDP_INTRODUCTION
    SIDE = Side.ARGS

    auth_key: int

    def encode(self) -> bytes:
        return FieldWriter().ubyte4(self.auth_key).bytes()

    @classmethod
    def decode(cls, data: bytes) -> Self:
        return cls(FieldReader(data).ubyte4("auth key"))


@control
@dataclass(frozen=True, slots=True)
class ClientShutdown(EmptyPayload, ControlPayload):
    """SHUTDOWN from the client: it is leaving."""

    COMMAND = ClientCommand.SHUTDOWN
    SIDE = Side.ARGS


@control
@dataclass(frozen=True, slots=True)
class ClientUdpConfirmation(EmptyPayload, ControlPayload):
    """UDP_CONFIRMATION from the client (over TCP): the server's UDP datagram arrived."""

    COMMAND = ClientCommand.UDP_CONFIRMATION
    SIDE = Side.ARGS


@control
@dataclass(frozen=True, slots=True)
class ClientTcpOnly(EmptyPayload, ControlPayload):
    """TCP_ONLY from the client: send it everything over TCP (§2.10)."""

    COMMAND = ClientCommand.TCP_ONLY
    SIDE = Side.ARGS

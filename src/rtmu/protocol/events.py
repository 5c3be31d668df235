"""Events the sans-I/O connections report, as frozen dataclasses (the h11 / wsproto style).

The two made once per data packet (:class:`DataReceived`, :class:`ReplyPacket`) are named tuples:
as immutable, built in one C call rather than a Python ``__init__`` (a map is a million packets).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from typing import NamedTuple

from .datalist import DataList


@dataclass(frozen=True, slots=True)
class ServerIntroduction:
    version_tag: str
    udp_port: int
    auth_key: int
    intro_key: int
    password_key: str
    protocol_version: str


@dataclass(frozen=True, slots=True)
class Connected:
    """The server accepted the login; the data list follows."""


@dataclass(frozen=True, slots=True)
class Rejected:
    reason: int
    text: str
    message: str
    """A readable sentence built from the reason code and text."""


@dataclass(frozen=True, slots=True)
class DataListReady:
    """The catalogue is complete (LISTGROUPANDFLAGS arrived); requests may use any name."""

    datalist: DataList


class DataReceived(NamedTuple):
    """A data packet no tracked request claimed: a broadcast, a subscription update, an untracked reply."""

    command: int
    name: str | None
    payload: bytes


@dataclass(frozen=True, slots=True, eq=False)
class ReplyId:
    """Names one tracked request (``ClientConnection.request_reply``): the key its waiter is kept under.

    Compared by identity (each request has its own): a cheap key on the per-packet path.
    """

    serial: int
    """Unique per connection, in the order the requests were sent."""
    number: int
    name: str


class ReplyError(Enum):
    """Why a tracked reply failed; the message says it in words."""

    TOO_LARGE = "too large"
    """Past the request's packet or byte bound; the rest of the reply is swallowed."""
    MALFORMED = "malformed"
    """The reply's own end test refused a packet (a broken or endless map)."""


class ReplyPacket(NamedTuple):
    """A data packet that belongs to a tracked request (handlers see it like any packet)."""

    reply: ReplyId
    payload: bytes
    swallowed: bool = False
    """Not for the request's waiter: it gave up earlier, or the reply failed at this very packet."""

    @property
    def command(self) -> int:
        return self.reply.number

    @property
    def name(self) -> str:
        return self.reply.name


@dataclass(frozen=True, slots=True)
class ReplyComplete:
    """The tracked reply ended; ``payloads`` is all of it (empty when streamed: already handed out)."""

    reply: ReplyId
    payloads: tuple[bytes, ...]


@dataclass(frozen=True, slots=True)
class ReplyFailed:
    """The tracked reply cannot be delivered; its remaining packets are swallowed, not misattributed."""

    reply: ReplyId
    reason: ReplyError
    message: str


@dataclass(frozen=True, slots=True)
class PeerShutdown:
    """The peer sent SHUTDOWN: it is closing the connection."""


@dataclass(frozen=True, slots=True)
class ClientIntroduced:
    """Server side: the client's INTRODUCTION was accepted."""

    user: str
    udp_port: int
    protocol_version: str
    client_type: int


@dataclass(frozen=True, slots=True)
class LoginRefused:
    """Server side: we sent REJECTED and the connection should close after the flush."""

    reason: int
    text: str


@dataclass(frozen=True, slots=True)
class RequestReceived:
    """Server side: REQUEST — subscribe to ``name`` every ``interval_ms`` (−1 = broadcasts only)."""

    number: int
    name: str
    interval_ms: int
    args: bytes
    new: bool
    """False when it only replaced the interval/arguments of an existing subscription."""


@dataclass(frozen=True, slots=True)
class RequestStopped:
    number: int
    name: str


@dataclass(frozen=True, slots=True)
class RequestOnce:
    """Server side: a packet whose command is a data number — run that data once."""

    number: int
    name: str
    args: bytes


@dataclass(frozen=True, slots=True)
class TcpOnlyRequested:
    """Server side: the client wants everything over TCP."""


@dataclass(frozen=True, slots=True)
class Ignored:
    """A packet that the protocol says to ignore in this state (kept for logs and tools)."""

    command: int
    why: str


Event = (
    ServerIntroduction
    | Connected
    | Rejected
    | DataListReady
    | DataReceived
    | ReplyPacket
    | ReplyComplete
    | ReplyFailed
    | PeerShutdown
    | ClientIntroduced
    | LoginRefused
    | RequestReceived
    | RequestStopped
    | RequestOnce
    | TcpOnlyRequested
    | Ignored
)

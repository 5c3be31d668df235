"""What decoding a capture yields, and one captured ArNetworking conversation's running state.

The decoder (:mod:`.session_decoder`) feeds each conversation's bytes through its own framing
decoders and data list; the items it yields are the dataclasses here, so readers of its output
(``rtmu decode``, replay, the golden tests) need not import the decoder itself.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Any

from ..protocol.commands import is_control_command
from ..protocol.datalist import DataList
from ..protocol.decoder import PacketDecoder
from . import Endpoint, Flow

C2S = "c2s"
S2C = "s2c"


# -- what comes out ---------------------------------------------------------------
@dataclass(slots=True)
class DecodedPacket:
    conn: int
    direction: str
    transport: str
    time: float | None
    command: int
    name: str | None
    length: int
    checksum_ok: bool
    payload: bytes
    fields: dict[str, Any]
    error: str | None = None
    note: str | None = None
    """A short remark: ``end of reply``, ``empty``, ``not decoded``…"""
    dropped_before: dict[str, int] | None = None
    """What the framing decoder threw away in this direction just before this packet."""

    @property
    def is_data(self) -> bool:
        return not is_control_command(self.command)


@dataclass(slots=True)
class DropReport:
    conn: int
    direction: str
    transport: str
    time: float | None
    counts: dict[str, int]


@dataclass(slots=True)
class TrailingDrops:
    """Drops that no later packet carries as ``dropped_before``: what ended a stream or a datagram.

    Only yielded by ``CaptureDecoder(report_trailing_drops=True)``: ``rtmu decode --json`` shows
    drops through the next packet's ``dropped_before``, so without these the garbage or cut-off
    packet at the very end of a stream would vanish from its output.
    """

    conn: int
    direction: str
    transport: str
    time: float | None
    counts: dict[str, int]


DecodeItem = DecodedPacket | DropReport | TrailingDrops


@dataclass(slots=True)
class DirectionTotals:
    packets: int = 0
    bytes: int = 0
    by_name: Counter[str] = field(default_factory=Counter)
    drops: Counter[str] = field(default_factory=Counter)


class Conversation:
    """One ArNetworking conversation: a TCP connection, a bare stream, or an orphan UDP flow."""

    def __init__(self, transport: str, flow: Flow | None, a: Endpoint, b: Endpoint) -> None:
        self.id: int | None = None
        self.transport = transport
        self.flow = flow
        self.ends = (a, b)
        self.server: Endpoint | None = flow.server if flow else None
        self.server_guessed = False
        self.datalist = DataList()
        self.decoders = {C2S: PacketDecoder(keep_bad=True), S2C: PacketDecoder(keep_bad=True)}
        self.totals = {C2S: DirectionTotals(), S2C: DirectionTotals()}
        self.pending_drops: dict[tuple[str, str], Counter[str]] = {}
        """Drops not yet attached to a packet, by (direction, transport)."""
        self.held: list[DecodeItem] = []
        self.held_overflow = 0
        self.ended: set[str] = set()
        self.first_time: float | None = None
        self.last_time: float | None = None
        self.udp_datagrams = 0
        self.udp_flows: set[tuple[Endpoint, Endpoint]] = set()
        # handshake facts (for UDP attribution and the summary)
        self.server_udp_port: int | None = None
        self.client_udp_port: int | None = None
        self.auth_key: int | None = None
        self.intro_key: int | None = None
        self.user: str | None = None
        self.rejected: str | None = None

    @property
    def client(self) -> Endpoint | None:
        if self.server is None:
            return None
        return self.ends[1] if self.server == self.ends[0] else self.ends[0]

    def direction_from(self, src: Endpoint) -> str:
        return S2C if src == self.server else C2S

    def touch(self, time: float | None) -> None:
        if time is None:
            return
        if self.first_time is None:
            self.first_time = time
        self.last_time = time

    @property
    def drops(self) -> Counter[str]:
        return self.totals[C2S].drops + self.totals[S2C].drops

"""What a capture reader hands to the session decoder: byte streams, gaps and datagrams.

Readers (pcap, pcapng, hex dump, raw bytes) all reduce their input to these few
events, so the ArNetworking side never cares where the bytes came from.
"""

from __future__ import annotations

from dataclasses import dataclass, field


class CaptureError(Exception):
    """The input cannot be read or is not a format we understand (one clear sentence)."""


@dataclass(frozen=True, slots=True, order=True)
class Endpoint:
    """One end of a conversation: an IP address and port (or a placeholder for a bare stream)."""

    host: str
    port: int

    def __str__(self) -> str:
        if ":" in self.host:
            return f"[{self.host}]:{self.port}"
        return f"{self.host}:{self.port}"


@dataclass(slots=True, eq=False)
class Flow:
    """One TCP connection (or one bare byte stream); ``server`` is None until something tells."""

    id: int
    transport: str
    """``tcp`` or ``stream`` (hex dump / raw bytes)."""
    first: Endpoint
    """The endpoint that sent the first segment we saw."""
    second: Endpoint
    server: Endpoint | None = None
    """Known when the capture holds the SYN (the side that accepted it is the server)."""

    def peer_of(self, end: Endpoint) -> Endpoint:
        return self.second if end == self.first else self.first


@dataclass(frozen=True, slots=True)
class StreamData:
    """In-order bytes of one direction of a flow."""

    flow: Flow
    src: Endpoint
    time: float | None
    data: bytes


@dataclass(frozen=True, slots=True)
class StreamGap:
    """Bytes of one direction that the capture never saw (lost segment, snap length)."""

    flow: Flow
    src: Endpoint
    time: float | None
    missing: int


@dataclass(frozen=True, slots=True)
class StreamEnd:
    """One direction ended (FIN, RST, or the end of the capture)."""

    flow: Flow
    src: Endpoint
    time: float | None


@dataclass(frozen=True, slots=True)
class Datagram:
    """One UDP datagram's payload (ArNetworking puts one packet in each)."""

    src: Endpoint
    dst: Endpoint
    time: float | None
    data: bytes
    truncated: bool = False


CaptureEvent = StreamData | StreamGap | StreamEnd | Datagram


@dataclass(slots=True)
class CaptureStats:
    """What the reader met besides ArNetworking bytes; shown in the summary."""

    kind: str = ""
    link_type: int | None = None
    frames: int = 0
    first_time: float | None = None
    last_time: float | None = None
    not_ip: int = 0
    """Frames that were not IPv4/IPv6 (ARP, …) or not TCP/UDP."""
    ip_fragments: int = 0
    """Fragmented IP packets (not reassembled; loopback captures never have them)."""
    truncated_frames: int = 0
    """Frames cut by the snap length."""
    retransmitted_bytes: int = 0
    out_of_order_segments: int = 0
    tcp_gaps: int = 0
    warnings: list[str] = field(default_factory=list)

"""Build capture files byte by byte for the capture and ``rtmu decode`` tests.

Written from the file-format specifications (libpcap, pcapng, Ethernet, IPv4/6,
TCP, UDP), independently of :mod:`rtmu.capture`, so a reader bug is not
mirrored here. Also small ArNetworking sessions (handshake + lists + data).
"""

from __future__ import annotations

import ipaddress
import struct
from dataclasses import dataclass, field

from rtmu.protocol.datalist import DataList
from rtmu.protocol.fields import FieldWriter
from rtmu.protocol.packet import encode_packet

SYN, FIN, RST, PSH, ACK = 0x02, 0x01, 0x04, 0x08, 0x10


# -- layers 3 and 4 ---------------------------------------------------------------
def _addr(text: str) -> bytes:
    return ipaddress.ip_address(text).packed


def tcp(sport: int, dport: int, seq: int, flags: int, payload: bytes = b"", ack: int = 0) -> bytes:
    header = struct.pack(">HHIIBBHHH", sport, dport, seq & 0xFFFFFFFF, ack, 5 << 4, flags, 65535, 0, 0)
    return header + payload


def udp(sport: int, dport: int, payload: bytes) -> bytes:
    return struct.pack(">HHHH", sport, dport, 8 + len(payload), 0) + payload


def ipv4(src: str, dst: str, protocol: int, body: bytes, *, fragment: bool = False) -> bytes:
    flags_offset = 0x2000 if fragment else 0x4000  # MF, or DF
    header = struct.pack(
        ">BBHHHBBH4s4s", 0x45, 0, 20 + len(body), 1, flags_offset, 64, protocol, 0, _addr(src), _addr(dst)
    )
    return header + body


def ipv6(src: str, dst: str, protocol: int, body: bytes, *, hop_by_hop: bool = False) -> bytes:
    if hop_by_hop:  # one 8-byte extension header in front of the transport header
        body = bytes((protocol, 0)) + b"\x01\x04\x00\x00\x00\x00" + body
        protocol = 0
    return struct.pack(">IHBB16s16s", 6 << 28, len(body), protocol, 64, _addr(src), _addr(dst)) + body


def ip_packet(src: str, dst: str, protocol: int, body: bytes) -> bytes:
    if ":" in src:
        return ipv6(src, dst, protocol, body)
    return ipv4(src, dst, protocol, body)


# -- link layers --------------------------------------------------------------------
def ethernet(ip: bytes, *, vlan: bool = False, pad_to: int = 0) -> bytes:
    ethertype = 0x86DD if ip[0] >> 4 == 6 else 0x0800
    head = b"\x02\x00\x00\x00\x00\x02" + b"\x02\x00\x00\x00\x00\x01"
    if vlan:
        head += struct.pack(">HH", 0x8100, 42)
    frame = head + struct.pack(">H", ethertype) + ip
    return frame.ljust(pad_to, b"\x00")  # Ethernet pads short frames; the IP length must win


def null_loopback(ip: bytes, byteorder: str = "little") -> bytes:
    family = 2 if ip[0] >> 4 == 4 else 30
    return family.to_bytes(4, byteorder) + ip  # type: ignore[arg-type]


def linux_sll(ip: bytes) -> bytes:
    protocol = 0x86DD if ip[0] >> 4 == 6 else 0x0800
    return struct.pack(">HHH8sH", 0, 772, 6, b"\x00" * 8, protocol) + ip


def linux_sll2(ip: bytes) -> bytes:
    protocol = 0x86DD if ip[0] >> 4 == 6 else 0x0800
    return struct.pack(">HHIHBB8s", protocol, 0, 1, 772, 0, 6, b"\x00" * 8) + ip


LINKS = {
    1: ethernet,
    0: null_loopback,
    108: lambda ip: null_loopback(ip, "big"),
    101: lambda ip: ip,
    12: lambda ip: ip,
    14: lambda ip: ip,
    113: linux_sll,
    276: linux_sll2,
}


# -- files ----------------------------------------------------------------------------
@dataclass(frozen=True)
class Frame:
    time: float
    data: bytes
    original_length: int | None = None


def pcap_file(
    frames: list[Frame], link_type: int = 1, *, big_endian: bool = False, nano: bool = False
) -> bytes:
    order = ">" if big_endian else "<"
    magic = 0xA1B23C4D if nano else 0xA1B2C3D4
    out = bytearray(struct.pack(order + "IHHiIII", magic, 2, 4, 0, 0, 262144, link_type))
    scale = 1_000_000_000 if nano else 1_000_000
    for f in frames:
        sec = int(f.time)
        frac = round((f.time - sec) * scale)
        orig = f.original_length if f.original_length is not None else len(f.data)
        out += struct.pack(order + "IIII", sec, frac, len(f.data), orig) + f.data
    return bytes(out)


def pcapng_file(
    frames: list[Frame], link_type: int = 1, *, big_endian: bool = False, nano: bool = False
) -> bytes:
    o = ">" if big_endian else "<"

    def block(kind: int, body: bytes) -> bytes:
        body = body + b"\x00" * (-len(body) % 4)
        length = 12 + len(body)
        return struct.pack(o + "II", kind, length) + body + struct.pack(o + "I", length)

    shb = block(0x0A0D0D0A, struct.pack(o + "IHHq", 0x1A2B3C4D, 1, 0, -1))
    options = b""
    if nano:
        options = struct.pack(o + "HH", 9, 1) + b"\x09\x00\x00\x00" + struct.pack(o + "HH", 0, 0)
    idb = block(1, struct.pack(o + "HHI", link_type, 0, 262144) + options)
    out = bytearray(shb + idb)
    scale = 1_000_000_000 if nano else 1_000_000
    for f in frames:
        ticks = round(f.time * scale)
        orig = f.original_length if f.original_length is not None else len(f.data)
        body = struct.pack(o + "IIIII", 0, ticks >> 32, ticks & 0xFFFFFFFF, len(f.data), orig) + f.data
        out += block(6, body)
    return bytes(out)


# -- a TCP conversation ---------------------------------------------------------------
@dataclass
class Conversation:
    """Segments of one TCP connection between a client and a server, in the order they are made."""

    client: tuple[str, int] = ("127.0.0.1", 50000)
    server: tuple[str, int] = ("127.0.0.1", 7272)
    client_isn: int = 1000
    server_isn: int = 5000
    time: float = 1700000000.0
    segments: list[tuple[float, bool, int, int, bytes]] = field(default_factory=list)
    """(time, from client, seq, flags, payload)"""

    def __post_init__(self) -> None:
        self.seq = {True: self.client_isn, False: self.server_isn}

    def _add(
        self, from_client: bool, flags: int, payload: bytes = b""
    ) -> tuple[float, bool, int, int, bytes]:
        self.time += 0.001
        seg = (self.time, from_client, self.seq[from_client], flags, payload)
        self.segments.append(seg)
        self.seq[from_client] = (self.seq[from_client] + len(payload) + (1 if flags & (SYN | FIN) else 0)) & (
            0xFFFFFFFF
        )
        return seg

    def handshake(self) -> Conversation:
        self._add(True, SYN)
        self._add(False, SYN | ACK)
        self._add(True, ACK)
        return self

    def send(self, from_client: bool, data: bytes, pieces: int = 1) -> Conversation:
        step = max(1, -(-len(data) // pieces))
        for i in range(0, len(data), step):
            self._add(from_client, PSH | ACK, data[i : i + step])
        return self

    def close(self) -> Conversation:
        self._add(True, FIN | ACK)
        self._add(False, FIN | ACK)
        self._add(True, ACK)
        return self

    def ip_packets(self) -> list[tuple[float, bytes]]:
        out = []
        for time, from_client, seq, flags, payload in self.segments:
            (sh, sp), (dh, dp) = (self.client, self.server) if from_client else (self.server, self.client)
            out.append((time, ip_packet(sh, dh, 6, tcp(sp, dp, seq, flags, payload))))
        return out

    def frames(self, link_type: int = 1) -> list[Frame]:
        wrap = LINKS[link_type]
        return [Frame(t, wrap(ip)) for t, ip in self.ip_packets()]


def udp_frame(
    time: float, src: tuple[str, int], dst: tuple[str, int], payload: bytes, link_type: int = 1
) -> Frame:
    return Frame(time, LINKS[link_type](ip_packet(src[0], dst[0], 17, udp(src[1], dst[1], payload))))


# -- ArNetworking content -------------------------------------------------------------
def server_intro(udp_port: int = 0, auth_key: int = 0x1E564427, intro_key: int = 0x35E51CAF) -> bytes:
    payload = (
        FieldWriter()
        .string("alpha")
        .ubyte2(udp_port)
        .ubyte4(auth_key)
        .ubyte4(intro_key)
        .string("key")
        .string("")
    )
    return encode_packet(2, payload.bytes())


def client_intro(udp_port: int = 0, user: str = "") -> bytes:
    payload = FieldWriter().ubyte2(udp_port).string(user).raw(b"\x11" * 16).string("").byte(0)
    return encode_packet(2, payload.bytes())


def catalogue(names: list[str], flags: dict[str, str] | None = None) -> DataList:
    flags = flags or {}
    return DataList.build(
        (n, f"{n} description", "", "", "Group", flags.get(n, "RETURN_SINGLE")) for n in names
    )


def server_greeting(datalist: DataList, udp_port: int = 0) -> tuple[bytes, bytes]:
    """(server INTRODUCTION, CONNECTED + the three lists) as the server sends them."""
    lists = b"".join(p.encode() for p in datalist.list_packets())
    return server_intro(udp_port), encode_packet(5) + lists


def request(number: int, interval: int, args: bytes = b"") -> bytes:
    return encode_packet(129, FieldWriter().ubyte2(number).byte4(interval).bytes() + args)


def update_numbers(x: int = 1000, y: int = -2000, th: int = 90) -> bytes:
    """An ``updateNumbers`` reply payload (§4.1)."""
    return struct.pack("<hiihhhhb", 130, x, y, th, 100, 5, 0, -128)

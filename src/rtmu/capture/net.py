"""Peel link, IP and TCP/UDP headers off a captured frame.

Link types: Ethernet (1, with VLAN tags), BSD loopback NULL (0) and LOOP (108),
raw IP (101, 12, 14, 228, 229), Linux cooked SLL (113) and SLL2 (276).
IPv4 and IPv6 (extension headers skipped). Fragments are not reassembled:
they are counted and skipped. Checksums are not verified, because loopback
captures carry unfilled ones (checksum offload).
"""

from __future__ import annotations

import ipaddress
import struct
from dataclasses import dataclass

from .base import Endpoint

ETHERNET = 1
NULL = 0
LOOP = 108
RAW_IP = (101, 12, 14, 228, 229)
LINUX_SLL = 113
LINUX_SLL2 = 276
SUPPORTED_LINK_TYPES = frozenset((ETHERNET, NULL, LOOP, LINUX_SLL, LINUX_SLL2, *RAW_IP))

_ETH_IPV4 = 0x0800
_ETH_IPV6 = 0x86DD
_VLAN_TAGS = (0x8100, 0x88A8, 0x9100)
_IPV6_EXTENSIONS = (0, 43, 60, 135, 139, 140)
TCP = 6
UDP = 17
FIN, SYN, RST, ACK = 0x01, 0x02, 0x04, 0x10


@dataclass(frozen=True, slots=True)
class Segment:
    """A TCP segment or UDP datagram with its addresses; ``lost`` bytes were cut by the snap length."""

    protocol: int
    src: Endpoint
    dst: Endpoint
    payload: bytes
    lost: int = 0
    seq: int = 0
    flags: int = 0


class NotTcpUdp(Exception):
    """The frame carries something else (ARP, ICMP, a fragment…); the reason is the message."""


def ip_payload(link_type: int, frame: bytes) -> bytes:
    """The IP packet inside a link-layer frame."""
    if link_type == ETHERNET:
        if len(frame) < 14:
            raise NotTcpUdp("short Ethernet frame")
        ethertype = frame[12] << 8 | frame[13]
        pos = 14
        while ethertype in _VLAN_TAGS and len(frame) >= pos + 4:
            ethertype = frame[pos + 2] << 8 | frame[pos + 3]
            pos += 4
        if ethertype not in (_ETH_IPV4, _ETH_IPV6):
            raise NotTcpUdp(f"ethertype 0x{ethertype:04x}")
        return frame[pos:]
    if link_type in (NULL, LOOP):
        return frame[4:]  # address family in either byte order; the IP version nibble decides
    if link_type == LINUX_SLL:
        return _cooked(frame, 14, 16)
    if link_type == LINUX_SLL2:
        return _cooked(frame, 0, 20)
    if link_type in RAW_IP:
        return frame
    raise NotTcpUdp(f"link type {link_type}")


def _cooked(frame: bytes, type_at: int, header: int) -> bytes:
    if len(frame) < header:
        raise NotTcpUdp("short cooked frame")
    protocol = frame[type_at] << 8 | frame[type_at + 1]
    if protocol not in (_ETH_IPV4, _ETH_IPV6):
        raise NotTcpUdp(f"protocol 0x{protocol:04x}")
    return frame[header:]


def parse_ip(packet: bytes, original_extra: int = 0) -> Segment:
    """Decode the IP and TCP/UDP headers; ``original_extra`` = bytes the snap length cut off."""
    if not packet:
        raise NotTcpUdp("empty IP packet")
    version = packet[0] >> 4
    if version == 4:
        if len(packet) < 20:
            raise NotTcpUdp("short IPv4 header")
        ihl = (packet[0] & 0x0F) * 4
        total = packet[2] << 8 | packet[3]
        if packet[6] & 0x3F or packet[7]:  # more-fragments flag or a fragment offset
            raise NotTcpUdp("IP fragment")
        protocol = packet[9]
        src = _ipv4(packet[12:16])
        dst = _ipv4(packet[16:20])
        end = total if total >= ihl else len(packet) + original_extra  # total 0: TSO on capture
        body = packet[ihl:end]
        body_length = end - ihl
    elif version == 6:
        if len(packet) < 40:
            raise NotTcpUdp("short IPv6 header")
        body_length = packet[4] << 8 | packet[5]
        protocol = packet[6]
        src = str(ipaddress.IPv6Address(packet[8:24]))
        dst = str(ipaddress.IPv6Address(packet[24:40]))
        pos = 40
        while protocol in _IPV6_EXTENSIONS or protocol == 44:
            if len(packet) < pos + 8:
                raise NotTcpUdp("short IPv6 extension header")
            if protocol == 44:
                raise NotTcpUdp("IP fragment")
            size = (packet[pos + 1] + 1) * 8
            protocol = packet[pos]
            pos += size
            body_length -= size
        body = packet[pos : pos + body_length]
    else:
        raise NotTcpUdp(f"IP version {version}")
    lost = max(0, body_length - len(body))
    if protocol == TCP:
        return _tcp(src, dst, body, lost)
    if protocol == UDP:
        return _udp(src, dst, body, lost)
    raise NotTcpUdp(f"IP protocol {protocol}")


def _ipv4(raw: bytes) -> str:
    return f"{raw[0]}.{raw[1]}.{raw[2]}.{raw[3]}"


def _tcp(src: str, dst: str, body: bytes, lost: int) -> Segment:
    if len(body) < 20:
        raise NotTcpUdp("TCP header cut by the snap length")
    sport, dport, seq = struct.unpack_from(">HHI", body)
    offset = (body[12] >> 4) * 4
    if offset < 20 or len(body) < offset:
        raise NotTcpUdp("bad TCP header length")
    return Segment(TCP, Endpoint(src, sport), Endpoint(dst, dport), body[offset:], lost, seq, body[13])


def _udp(src: str, dst: str, body: bytes, lost: int) -> Segment:
    if len(body) < 8:
        raise NotTcpUdp("UDP header cut by the snap length")
    sport, dport, length = struct.unpack_from(">HHH", body)
    payload = body[8:length] if length >= 8 else body[8:]
    lost = max(0, length - 8 - len(payload)) if length >= 8 else lost
    return Segment(UDP, Endpoint(src, sport), Endpoint(dst, dport), payload, lost)

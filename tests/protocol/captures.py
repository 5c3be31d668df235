"""Just enough libpcap reading for the codec tests: the TCP byte streams of a capture, per direction.

The shared captures are classic little-endian pcap, Ethernet, IPv4, recorded on loopback, so a
segment is placed by its sequence number and retransmissions are dropped; no more is needed here.
"""

from __future__ import annotations

import struct
from pathlib import Path

Direction = tuple[str, int, str, int]
"""(source address, source port, destination address, destination port)"""


def tcp_streams(path: Path) -> dict[Direction, bytes]:
    data = path.read_bytes()
    if data[:4] != b"\xd4\xc3\xb2\xa1" or struct.unpack_from("<I", data, 20)[0] != 1:
        raise ValueError(f"{path}: expected little-endian pcap with Ethernet frames")
    segments: dict[Direction, dict[int, bytes]] = {}
    first_seq: dict[Direction, int] = {}
    pos = 24
    while pos + 16 <= len(data):
        captured = struct.unpack_from("<I", data, pos + 8)[0]
        frame = data[pos + 16 : pos + 16 + captured]
        pos += 16 + captured
        if frame[12:14] != b"\x08\x00" or frame[23] != 6:  # IPv4 carrying TCP
            continue
        ip = frame[14:]
        ip_header = (ip[0] & 0x0F) * 4
        ip_total = struct.unpack_from(">H", ip, 2)[0]
        tcp = ip[ip_header:ip_total]
        sport, dport, seq = struct.unpack_from(">HHI", tcp)
        payload = tcp[(tcp[12] >> 4) * 4 :]
        key = (".".join(map(str, ip[12:16])), sport, ".".join(map(str, ip[16:20])), dport)
        if tcp[13] & 0x02:  # SYN: the stream starts after it
            first_seq[key] = seq + 1
        if payload:
            segments.setdefault(key, {}).setdefault(seq, payload)
    streams: dict[Direction, bytes] = {}
    for key, by_seq in segments.items():
        expected = first_seq.get(key, min(by_seq))
        out = bytearray()
        for seq in sorted(by_seq):
            offset = seq - expected
            if offset < 0:
                continue  # sequence wrap does not happen in these short sessions
            if offset > len(out):
                raise ValueError(f"{path}: gap in {key} at sequence {seq}")
            out += by_seq[seq][len(out) - offset :]
        streams[key] = bytes(out)
    return streams

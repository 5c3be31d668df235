"""Nothing that recovers a password goes into a recording: the login's digest is recorded as zeros.

The client proves its password with MD5(server key + the connection's password key + password);
the password key travels in the server's introduction, so a recorded digest next to it lets a
weak password be found offline in seconds — from a file people share for support. The client's
INTRODUCTION packet is therefore recorded with its 16 digest bytes zeroed and its checksum made
good again, so ``rtmu decode`` still shows a valid packet. Replay never needs the digest (its
client logs in to no one). The file's metadata says so (:data:`METADATA`).
"""

from __future__ import annotations

from ..protocol.commands import ClientCommand
from ..protocol.decoder import PacketDecoder
from ..protocol.errors import ProtocolError
from ..protocol.packet import Packet, encode_packet
from ..protocol.payloads.control import DIGEST_LENGTH, ClientIntroduction

METADATA = {"login_digest": "zeroed: the password digest of each login is not recorded"}
LOOK_BYTES = 4096
"""The client's INTRODUCTION is its first packet: past this many bytes a connection is not looked at."""


class LoginScrubber:
    """One connection's client→server bytes: the INTRODUCTION's digest zeroed, everything else as is."""

    __slots__ = ("_done", "_seen")

    def __init__(self) -> None:
        self._done = False
        self._seen = 0

    def __call__(self, data: bytes) -> bytes:
        if self._done:
            return data
        self._seen += len(data)
        if self._seen > LOOK_BYTES:
            self._done = True
        decoder = PacketDecoder()
        packets = decoder.feed(data)
        if decoder.buffered or decoder.stats.garbage_bytes:
            # Not whole packets (our client always writes whole ones): rewrite nothing, but never pass a
            # digest on — a chunk holding an INTRODUCTION that cannot be rewritten is dropped.
            return b"" if _holds_introduction(packets) else data
        if not _holds_introduction(packets):
            return data
        self._done = True
        out = []
        for packet in packets:
            payload = packet.payload
            if packet.command == ClientCommand.INTRODUCTION:
                payload = _zeroed(payload)
            out.append(encode_packet(packet.command, payload))
        return b"".join(out)


def _holds_introduction(packets: list[Packet]) -> bool:
    return any(p.command == ClientCommand.INTRODUCTION for p in packets)


def _zeroed(payload: bytes) -> bytes:
    """The INTRODUCTION's payload with the digest's 16 bytes zeroed, every other byte as it was."""
    try:
        ClientIntroduction.decode(payload)
    except ProtocolError:
        return b""  # not an introduction we can read: record nothing of it rather than a digest
    start = payload.index(b"\0", 2) + 1  # after the UDP port (2 bytes) and the user name's NUL
    return payload[:start] + bytes(DIGEST_LENGTH) + payload[start + DIGEST_LENGTH :]

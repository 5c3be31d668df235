"""What ``rtmu decode`` may be told about its input: named apart from the readers, so that its
parser (and ``--help``) offers them without loading a reader."""

from __future__ import annotations

FORMATS = ("auto", "pcap", "hex", "raw")
"""Input formats: detected, a pcap/pcapng capture, a hex dump, raw bytes."""
DIRECTIONS = ("auto", "c2s", "s2c")
"""Who sent hex or raw bytes: guessed from the packets, the client, the server."""

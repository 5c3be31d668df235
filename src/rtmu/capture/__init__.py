"""Reading captured traffic (pcap, pcapng, hex dumps, raw bytes) for ``rtmu decode`` and the tests.

File parsing only: the ArNetworking side lives in :mod:`rtmu.capture.session_decoder`.
"""

from .base import (
    CaptureError,
    CaptureEvent,
    CaptureStats,
    Datagram,
    Endpoint,
    Flow,
    StreamData,
    StreamEnd,
    StreamGap,
)
from .hexdump import parse_hex
from .reader import FORMATS, CaptureSource, UnreadableInput, open_capture

__all__ = [
    "FORMATS",
    "CaptureError",
    "CaptureEvent",
    "CaptureSource",
    "CaptureStats",
    "Datagram",
    "Endpoint",
    "Flow",
    "StreamData",
    "StreamEnd",
    "StreamGap",
    "UnreadableInput",
    "open_capture",
    "parse_hex",
]

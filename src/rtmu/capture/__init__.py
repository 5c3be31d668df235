"""Reading captured traffic (pcap, pcapng, hex dumps, raw bytes) for ``rtmu decode`` and the tests.

File parsing only: the ArNetworking side lives in :mod:`rtmu.capture.session_decoder`. The names
below are imported on first use: the flight recorder reads the raw channel's layout
(``capture.recorded``) without loading the pcap readers.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..protocol import lazy

if TYPE_CHECKING:
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

_BASE = ("CaptureError", "CaptureEvent", "CaptureStats", "Datagram", "Endpoint", "Flow", "StreamData",
         "StreamEnd", "StreamGap")  # fmt: skip
__getattr__ = lazy.exports(
    __name__,
    {
        **dict.fromkeys(_BASE, "base"),
        "parse_hex": "hexdump",
        **dict.fromkeys(("FORMATS", "CaptureSource", "UnreadableInput", "open_capture"), "reader"),
    },
)

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

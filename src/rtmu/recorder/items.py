"""What the network and UI threads hand to a recording's writer thread: plain values, made in microseconds.

Producers never encode anything: they stamp the wall-clock time and enqueue one of
these; the writer thread turns them into MCAP messages (``convert``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ..values.state import StateChange


@dataclass(frozen=True, slots=True)
class RawChunk:
    """Bytes read from (``s2c``) or written to (``c2s``) connection ``conn``, exactly as they were."""

    conn: int
    direction: str
    data: bytes
    at_ns: int


@dataclass(frozen=True, slots=True)
class LinkOpened:
    """Connection ``conn`` to ``host:port`` is open; raw chunks of it follow."""

    conn: int
    host: str
    port: int
    at_ns: int


@dataclass(frozen=True, slots=True)
class Published:
    """A typed change the session published (robot, map, camera, connection, health …)."""

    change: StateChange
    at_ns: int


@dataclass(frozen=True, slots=True)
class Event:
    """A JSON record for one of the event topics (notices, intents, lease, stops)."""

    topic: str
    record: dict[str, Any]
    at_ns: int


Item = RawChunk | LinkOpened | Published | Event

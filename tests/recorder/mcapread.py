"""Reading a recording back with the ``mcap`` package (not with anything of RTMU's writer side)."""

from __future__ import annotations

import json
import struct
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mcap.exceptions import McapError
from mcap.reader import NonSeekingReader, make_reader


@dataclass(frozen=True, slots=True)
class Message:
    topic: str
    schema: str
    encoding: str
    data: bytes
    log_time: int

    def json(self) -> Any:
        assert self.encoding == "json", self.topic
        return json.loads(self.data)


@dataclass
class Read:
    messages: list[Message] = field(default_factory=list)
    cut_short: str | None = None
    """Why reading stopped before the end (a file cut by a crash), or None."""

    def topic(self, topic: str) -> list[Message]:
        return [m for m in self.messages if m.topic == topic]

    def records(self, topic: str) -> list[Any]:
        return [m.json() for m in self.topic(topic)]

    def counts(self) -> Counter[str]:
        return Counter(m.topic for m in self.messages)

    def schemas(self) -> dict[str, tuple[str, str]]:
        return {m.topic: (m.schema, m.encoding) for m in self.messages}


def read(path: Path) -> Read:
    """Every message in file order; a file cut short is read up to its last complete chunk."""
    out = Read()
    with path.open("rb") as f:
        try:
            for schema, channel, message in NonSeekingReader(f).iter_messages(log_time_order=False):
                name = schema.name if schema is not None else ""
                out.messages.append(
                    Message(
                        channel.topic, name, channel.message_encoding, bytes(message.data), message.log_time
                    )
                )
        except (McapError, EOFError, struct.error) as exc:  # struct.error: cut inside a record's length
            out.cut_short = str(exc) or type(exc).__name__
    return out


def summary_counts(path: Path) -> dict[str, int]:
    """Messages per topic from the file's own summary (only a finished file has one)."""
    with path.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None and summary.statistics is not None, f"{path} has no summary: not finished"
    counts = summary.statistics.channel_message_counts
    return {channel.topic: counts.get(cid, 0) for cid, channel in summary.channels.items()}

"""One connection of a recording, read back for replay: the server's bytes with their times and gates.

A replay rebuilds the window's state by feeding the recorded server bytes to a fresh
session (the same client code as live), so the map, robot, trail, sonar, navigation and
banners come out as they did. Replies must not reach the client before the request they
answer, so each server chunk carries a *gate*: how many of the client's own packets had
been written before it arrived live. Packets a replay never sends — drive commands,
stops, pings, operator actions, camera requests — are left out of that count on both
sides (:func:`counted`), so the gate means the same thing live and replayed. Camera
pictures are taken from the recording's ``CompressedImage`` channel instead (the live
client asked for them from its window timer).

The file is untrusted: sizes are bounded, a file cut short is read up to its last
complete chunk, and a file without a raw channel is a clear error.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from ..capture.base import CaptureError, CaptureStats, StreamData
from ..capture.conversation import C2S, DecodedPacket
from ..capture.mcap_bounded import BoundedMcap
from ..capture.recorded import CONNECTION_TOPIC, recorded_events
from ..capture.session_decoder import CaptureDecoder
from ..client.health import PING_CANDIDATES
from ..protocol.decoder import PacketDecoder
from ..protocol.motion import MOTION_REQUESTS, is_motion
from . import topics

NOT_REPLAYED = MOTION_REQUESTS | frozenset(
    {"setSafeDrive", "localizeToPose", "popupClicked", "say", "sendVideo", "getSafeDrive", *PING_CANDIDATES}
)
"""Client packets that come from the operator or a timer, never from the server's bytes alone."""
MAX_IMAGE = 16 * 1024 * 1024
MAX_REPLAY_BYTES = 512 * 1024 * 1024
"""Server bytes of one connection a replay keeps in memory (hours of status and sonar), each recorded
chunk counted with :data:`CHUNK_OVERHEAD`: a file of millions of 8-byte chunks is refused as well."""
CHUNK_OVERHEAD = 160
"""What keeping one recorded chunk costs beside its bytes (its object, its bytes' header, its slot)."""
REPLAY_BUDGET = 8 * 1024 * 1024 * 1024
"""Uncompressed bytes a replayed file's chunks may claim in all (checked before any is decompressed)."""
MAX_IMAGE_BYTES = 256 * 1024 * 1024
"""Camera pictures a replay keeps in memory; beyond it every other one is left out (and it says so)."""


class ReplayFileError(Exception):
    """The file is not a replayable RTMU recording (the message says why, for the operator)."""


def not_replayed(name: str | None) -> bool:
    return name is not None and (name in NOT_REPLAYED or name.startswith("getPicture"))


@dataclass(frozen=True, slots=True)
class ServerChunk:
    at_ns: int
    data: bytes
    gate: int
    """Counted client packets written before this chunk arrived live."""


@dataclass
class RecordedConnection:
    """What a replay needs of one recorded connection."""

    path: Path
    conn: int
    host: str
    port: int
    chunks: list[ServerChunk]
    start_ns: int
    end_ns: int
    uncounted: frozenset[int] = frozenset()
    """Client command numbers left out of the gate count."""
    motion: frozenset[int] = frozenset()
    """Client command numbers a replay link refuses."""
    images: list[tuple[int, bytes]] = field(default_factory=list)
    """(time, JPEG) of each camera picture of this connection."""
    connections: int = 1
    """How many connections the file holds (the first is replayed unless another is asked for)."""
    warnings: list[str] = field(default_factory=list)

    @property
    def duration_ns(self) -> int:
        return self.end_ns - self.start_ns

    def counted(self, data: bytes, decoder: PacketDecoder) -> int:
        """How many packets in ``data`` (client bytes) count toward the gates."""
        return sum(1 for p in decoder.feed(data) if p.command not in self.uncounted)


def load(path: Path, conn: int | None = None) -> RecordedConnection:
    """Connection ``conn`` (default: the first) of the recording at ``path``; ReplayFileError if none."""
    stats = CaptureStats()
    index = 1 if conn is None else conn
    flows: list[int] = []
    mine: list[StreamData] = []
    size = 0
    try:
        for event in recorded_events(path, stats, budget=REPLAY_BUDGET):
            if not isinstance(event, StreamData):
                continue
            if event.flow.id not in flows:
                flows.append(event.flow.id)
            if len(flows) >= index and event.flow.id == flows[index - 1]:
                size += len(event.data) + CHUNK_OVERHEAD
                if size > MAX_REPLAY_BYTES:
                    raise ReplayFileError(
                        f"connection {index} of {path.name} holds over {MAX_REPLAY_BYTES >> 20} MB of "
                        "ArNetworking bytes (or millions of tiny chunks): too long to replay in one piece"
                    )
                mine.append(event)
    except ReplayFileError:
        raise
    except CaptureError as exc:  # a bomb, a file that is no recording: its reason as it stands
        raise ReplayFileError(str(exc)) from None
    except Exception as exc:
        raise ReplayFileError(str(exc)) from None
    if not flows:
        raise ReplayFileError(f"{path.name} holds no recorded ArNetworking bytes to replay")
    if not mine:
        raise ReplayFileError(f"{path.name} holds {len(flows)} connection(s); there is no connection {index}")
    names: dict[int, str | None] = {}
    for item in CaptureDecoder(decode_payloads=False).run(iter(mine)):
        if isinstance(item, DecodedPacket) and item.direction == C2S:
            names.setdefault(item.command, item.name)
    uncounted = frozenset(c for c, n in names.items() if not_replayed(n))
    motion = frozenset(c for c, n in names.items() if n is not None and is_motion(n))  # refused outright
    recorded = RecordedConnection(
        path,
        index,
        mine[0].flow.second.host,
        mine[0].flow.second.port,
        [],
        start_ns=_ns(mine[0].time),
        end_ns=_ns(mine[-1].time),
        uncounted=uncounted,
        motion=motion,
        connections=len(flows),
        warnings=list(stats.warnings),
    )
    decoder = PacketDecoder()
    count = 0
    for event in mine:
        if event.src == event.flow.second:  # from the server
            recorded.chunks.append(ServerChunk(_ns(event.time), event.data, count))
        else:
            count += recorded.counted(event.data, decoder)
    recorded.images = _bounded(_images(path, index, recorded.start_ns, recorded.end_ns), recorded.warnings)
    return recorded


def _bounded(pictures: Iterator[tuple[int, bytes]], warnings: list[str]) -> list[tuple[int, bytes]]:
    """The pictures, thinned to one in 2, 4, 8 … whenever they outgrow :data:`MAX_IMAGE_BYTES`."""
    kept: list[tuple[int, bytes]] = []
    total = 0
    stride = 1
    for n, (at, jpeg) in enumerate(pictures):
        if n % stride:
            continue
        kept.append((at, jpeg))
        total += len(jpeg)
        while total > MAX_IMAGE_BYTES and len(kept) > 1:
            kept = kept[::2]
            total = sum(len(j) for _, j in kept)
            stride *= 2
    if stride > 1:
        warnings.append(f"camera pictures thinned to 1 in {stride} to fit in memory")
    return kept


def _ns(seconds: float | None) -> int:
    return round((seconds or 0.0) * 1e9)


def _images(path: Path, conn: int, start_ns: int, end_ns: int) -> Iterator[tuple[int, bytes]]:
    """The camera pictures logged while connection ``conn`` was the current one."""
    current = 0
    with path.open("rb") as f:
        reader = BoundedMcap(f, budget=REPLAY_BUDGET)
        try:
            for _schema, channel, message in reader.messages():
                if channel.topic == CONNECTION_TOPIC:
                    try:
                        current = int(json.loads(message.data).get("conn", 0))
                    except (ValueError, TypeError, AttributeError):
                        continue
                elif channel.topic == topics.CAMERA and current == conn and start_ns <= message.log_time:
                    if message.log_time > end_ns + 1_000_000_000:
                        continue
                    jpeg = compressed_image_data(bytes(message.data))
                    if jpeg is not None:
                        yield message.log_time, jpeg
        except Exception:  # cut short: the pictures up to there
            return


def compressed_image_data(message: bytes) -> bytes | None:
    """Field 2 (``data``) of a protobuf ``foxglove.CompressedImage``; None when the bytes do not parse."""
    pos = 0
    end = len(message)
    found: bytes | None = None
    while pos < end:
        key, pos = _varint(message, pos)
        if key is None:
            return None
        number, wire = key >> 3, key & 7
        if wire == 0:
            _, pos = _varint(message, pos)
        elif wire == 2:
            size, pos = _varint(message, pos)
            if size is None or size > MAX_IMAGE or pos + size > end:
                return None
            if number == 2:
                found = message[pos : pos + size]
            pos += size
        elif wire == 1:
            pos += 8
        elif wire == 5:
            pos += 4
        else:
            return None
        if pos is None:
            return None
    return found


def _varint(data: bytes, pos: int) -> tuple[int | None, int]:
    value = 0
    for shift in range(0, 64, 7):
        if pos >= len(data):
            return None, len(data)
        byte = data[pos]
        pos += 1
        value |= (byte & 0x7F) << shift
        if not byte & 0x80:
            return value, pos
    return None, len(data)

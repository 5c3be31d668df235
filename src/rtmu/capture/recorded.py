"""An RTMU recording's raw channel: its layout (shared with the writer) and its reading for ``rtmu decode``.

A recording (``rtmu.recorder``) is an MCAP file. Its raw channel keeps every byte
chunk of every ArNetworking connection exactly as it crossed the socket: topic
:data:`RAW_TOPICS` ``[direction]``, the chunk as the message, the wall-clock time
it was read or written as the log time. A message on :data:`CONNECTION_TOPIC`
(JSON ``{"conn": N, "host": …, "port": …}``) says that the raw chunks after it,
in file order, belong to connection ``N`` (a reconnect starts a new one). Reading
it back yields the same :class:`~rtmu.capture.base.CaptureEvent`s a pcap does, so
``rtmu decode`` explains a recording with the same decoder.

The file is untrusted like any capture. A file cut short by a crash or a power
loss is read up to its last complete chunk and the shortfall becomes a warning. Chunks are
weighed before they are decompressed (:mod:`.mcap_bounded`): a decompression bomb is refused
with the reason (:class:`~rtmu.capture.mcap_bounded.McapBoundError`), never inflated.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from .base import CaptureError, CaptureEvent, CaptureStats, Endpoint, Flow, StreamData, StreamEnd
from .mcap_bounded import DEFAULT_BUDGET, BoundedMcap, McapBoundError

MCAP_MAGIC = b"\x89MCAP0\r\n"
C2S = "c2s"
S2C = "s2c"
RAW_TOPICS = {C2S: "/aria/raw/c2s", S2C: "/aria/raw/s2c"}
"""Direction → topic of the exact bytes."""
CONNECTION_TOPIC = "/aria/raw/connection"
RAW_ENCODING = "arnetworking"
"""The raw channels' message encoding: ArNetworking's own framing, bytes exactly as sent."""
RAW_SCHEMA = "rtmu.ArNetworkingBytes"
CLIENT = Endpoint("rtmu", 0)
"""The recording side (the operator's client) of every recorded connection."""
MAX_HOST = 255


def connection_record(conn: int, host: str, port: int) -> dict[str, Any]:
    """The :data:`CONNECTION_TOPIC` message that starts connection ``conn``."""
    return {"conn": conn, "host": host, "port": port}


def _server_of(data: bytes) -> tuple[int, Endpoint] | None:
    """(conn, server endpoint) from a connection message; None when it is not one we can trust."""
    try:
        record = json.loads(data)
    except (ValueError, UnicodeDecodeError):
        return None
    if not isinstance(record, dict):
        return None
    conn, host, port = record.get("conn"), record.get("host"), record.get("port")
    if not (isinstance(conn, int) and isinstance(host, str) and isinstance(port, int)):
        return None
    if isinstance(conn, bool) or isinstance(port, bool) or not 0 <= port <= 65535 or len(host) > MAX_HOST:
        return None
    return conn, Endpoint(host, port)


def recorded_events(
    path: Path, stats: CaptureStats, *, budget: int = DEFAULT_BUDGET
) -> Iterator[CaptureEvent]:
    """The raw channel of the recording at ``path`` as stream events, one flow per connection.

    ``budget``: the uncompressed bytes the file's chunks may claim in all. A file that asks for more
    than a recording may (a decompression bomb) raises :class:`CaptureError` saying so, before the
    chunk is inflated."""
    flows: dict[int, Flow] = {}
    current: Flow | None = None
    last: float | None = None
    try:
        f = path.open("rb")
    except OSError as exc:
        raise CaptureError(f"cannot read {path}: {exc.strerror or exc}") from exc
    with f:
        reader = BoundedMcap(f, budget=budget)
        try:
            for _schema, channel, message in reader.messages():
                at = message.log_time / 1e9
                if channel.topic == CONNECTION_TOPIC:
                    known = _server_of(message.data)
                    if known is None:
                        stats.warnings.append("a connection record that is not RTMU's was skipped")
                        continue
                    conn, server = known
                    current = flows.get(conn)
                    if current is None:
                        current = flows[conn] = Flow(len(flows) + 1, "tcp", CLIENT, server, server=server)
                    continue
                if channel.topic not in RAW_TOPICS.values():
                    continue
                direction = C2S if channel.topic == RAW_TOPICS[C2S] else S2C
                if current is None:  # raw bytes before any connection record: still one conversation
                    current = flows[0] = Flow(1, "tcp", CLIENT, Endpoint("server", 0), server=None)
                stats.frames += 1
                if stats.first_time is None:
                    stats.first_time = at
                last = at
                src = CLIENT if direction == C2S else current.second
                yield StreamData(current, src, at, bytes(message.data))
        except McapBoundError as exc:  # a bomb is no crash's cut: refused, whatever came before it
            raise CaptureError(f"{path} is refused: {exc}") from None
        except Exception as exc:  # untrusted: cut off, a lying record or chunk size, a bad chunk…
            if stats.frames == 0 and not flows:
                raise CaptureError(f"{path} is not a readable MCAP recording: {unreadable(exc)}") from None
            stats.warnings.append(
                "the recording ends early (cut short by a crash or a full disk?): read up to there "
                f"({unreadable(exc)})"
            )
    stats.last_time = last
    if not flows:
        stats.warnings.append(f"{path.name} has no RTMU raw channel ({RAW_TOPICS[S2C]}): nothing to decode")
    for flow in flows.values():
        yield StreamEnd(flow, CLIENT, last)
        yield StreamEnd(flow, flow.second, last)


def unreadable(exc: BaseException) -> str:
    """Why an MCAP file could not be read, in plain words (the reader's own errors may be empty)."""
    from mcap.exceptions import EndOfFile, InvalidMagic

    if isinstance(exc, InvalidMagic):
        return "it does not start as an MCAP file does (it is not a recording)"
    if isinstance(exc, (EndOfFile, EOFError)) or "unpack requires a buffer" in str(exc):
        return "it is cut short: it ends in the middle of a record"
    return str(exc) or type(exc).__name__

"""The raw channel holds the exact bytes of every connection: decoding it gives the packets that were live.

A spy link under the recorder's tee keeps what really crossed the socket, in order.
The recording's raw channel must hold the same bytes, per connection and direction,
and ``rtmu decode``'s decoder must find in the file exactly the packets it finds in
the live bytes — across a reconnect, which starts a second connection in the same file.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from client.uiqueue import eventually
from rtmu.capture import Endpoint, Flow, StreamData, StreamEnd, open_capture
from rtmu.capture.conversation import DecodedPacket
from rtmu.capture.recorded import RAW_TOPICS
from rtmu.capture.session_decoder import CaptureDecoder
from rtmu.client.link import Link, open_tcp
from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.protocol.commands import ClientCommand
from rtmu.recorder import Recorder, RecorderConfig
from rtmu.sim import SimConfig, SimThread
from rtmu.values.intents import RequestPicture
from rtmu.values.target import Target

from .mcapread import read
from .simsession import ARENA


class SpyLink:
    """Keeps every chunk read and written on one connection, in order."""

    def __init__(self, inner: Link, log: list[tuple[int, str, bytes]], conn: int) -> None:
        self.inner, self.log, self.conn = inner, log, conn

    async def read(self, max_bytes: int) -> bytes:
        data = await self.inner.read(max_bytes)
        if data:
            self.log.append((self.conn, "s2c", data))
        return data

    def write(self, data: bytes) -> None:
        self.log.append((self.conn, "c2s", bytes(data)))
        self.inner.write(data)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)


def packets(items: Any) -> list[tuple[int, str, int, str | None, bytes, bool]]:
    return [
        (p.conn, p.direction, p.command, p.name, p.payload, p.checksum_ok)
        for p in items
        if isinstance(p, DecodedPacket)
    ]


def live_packets(log: list[tuple[int, str, bytes]]) -> list[tuple[int, str, int, str | None, bytes, bool]]:
    client = Endpoint("spy", 0)
    flows: dict[int, Flow] = {}
    events: list[Any] = []
    for conn, direction, data in log:
        server = Endpoint("127.0.0.1", 1)
        flow = flows.setdefault(conn, Flow(conn, "tcp", client, server, server=server))
        events.append(StreamData(flow, client if direction == "c2s" else server, None, data))
    for flow in flows.values():
        events += [StreamEnd(flow, flow.first, None), StreamEnd(flow, flow.second, None)]
    return packets(CaptureDecoder().run(events))


def zero_digest(
    p: tuple[int, str, int, str | None, bytes, bool],
) -> tuple[int, str, int, str | None, bytes, bool]:
    """A live client INTRODUCTION as recorded: the 16 digest bytes after the user name zeroed."""
    conn, direction, command, name, payload, ok = p
    if direction != "c2s" or command != ClientCommand.INTRODUCTION:
        return p
    at = payload.index(b"\0", 2) + 1  # UDP port (2 bytes), the user name and its NUL
    assert payload[at : at + 16] != bytes(16), "a live login carries a digest"
    return conn, direction, command, name, payload[:at] + bytes(16) + payload[at + 16 :], ok


def test_the_raw_channel_decodes_to_exactly_the_live_packets(tmp_path: Path) -> None:
    log: list[tuple[int, str, bytes]] = []
    opened: list[int] = []

    async def spy_opener(host: str, port: int) -> Link:
        opened.append(len(opened) + 1)
        return SpyLink(await open_tcp(host, port), log, opened[-1])  # type: ignore[return-value]

    out = tmp_path / "session.mcap"
    recorder = Recorder(RecorderConfig(tmp_path, path=out))
    with SimThread(SimConfig(port=0, map_path=ARENA, seed=1)) as sim:
        runner = ClientRunner(config=SessionConfig(), opener=recorder.opener(spy_opener))
        recorder.attach(runner)
        with runner:
            runner.connect(Target("127.0.0.1", sim.port)).result(10)
            runner.call(runner._session.dispatch, RequestPicture())
            time.sleep(0.5)
            runner.connect(Target("127.0.0.1", sim.port)).result(10)  # the same robot: a second connection
            runner.call(runner._session.dispatch, RequestPicture())
            time.sleep(0.3)
        recorder.close()
    assert opened == [1, 2]
    assert [r.path for r in recorder.recordings] == [out], "both connections in one file"

    got = read(out)
    assert got.cut_short is None
    connections = [m.json() for m in got.topic("/aria/raw/connection")]
    assert [c["conn"] for c in connections] == [1, 2] and connections[0]["port"] == sim.port
    for conn in (1, 2):
        for direction in ("c2s", "s2c"):
            live = b"".join(d for c, dr, d in log if c == conn and dr == direction)
            assert live, (conn, direction)
    recorded = {d: b"".join(m.data for m in got.topic(t)) for d, t in RAW_TOPICS.items()}
    assert recorded["s2c"] == b"".join(d for _, dr, d in log if dr == "s2c")
    live_c2s = b"".join(d for _, dr, d in log if dr == "c2s")
    differ = [i for i, (a, b) in enumerate(zip(recorded["c2s"], live_c2s, strict=True)) if a != b]
    # Only each login's password digest (16 bytes, recorded as zeros) and its packet's checksum differ.
    assert 0 < len(differ) <= 2 * (16 + 2), differ

    source = open_capture(out)
    assert source.kind == "mcap"
    from_file = packets(CaptureDecoder().run(source.events()))
    live = [zero_digest(p) for p in live_packets(log)]
    assert len(live) > 50 and any(p[3] == "getPictureCam1" and p[1] == "s2c" for p in live)
    assert sum(p[2] == ClientCommand.INTRODUCTION and p[1] == "c2s" for p in live) == 2
    assert from_file == live, "every packet as it was live, the digest zeroed, every checksum good"
    assert not source.stats.warnings


def _subscribed_data_arrived(runner: ClientRunner) -> bool:
    """The current connection has delivered a few subscribed packets (status among them)."""
    client = runner.session.client if runner.session is not None else None
    return client is not None and client.packets_received >= 5


def test_raw_chunks_after_a_reconnect_belong_to_the_new_connection(tmp_path: Path) -> None:
    """A connection record before each connection's chunks: the decoder keeps their data lists apart."""
    out = tmp_path / "two.mcap"
    recorder = Recorder(RecorderConfig(tmp_path, path=out))
    with SimThread(SimConfig(port=0, seed=1)) as sim:
        runner = ClientRunner(config=SessionConfig(fetch_map=False), opener=recorder.opener())
        recorder.attach(runner)
        with runner:
            runner.connect(Target("127.0.0.1", sim.port)).result(10)
            eventually(lambda: len(recorder.recordings) == 1)
            # Status must have flowed on the first connection before it is replaced (a loaded
            # machine once replaced it before its first updateNumbers).
            eventually(lambda: _subscribed_data_arrived(runner))
            runner.connect(Target("127.0.0.1", sim.port)).result(10)
            eventually(lambda: _subscribed_data_arrived(runner))
            time.sleep(0.3)
        recorder.close()
    source = open_capture(out)
    items = packets(CaptureDecoder().run(source.events()))
    by_conn = {conn: [p for p in items if p[0] == conn] for conn in (1, 2)}
    for conn, found in by_conn.items():
        names = [p[3] for p in found]
        assert names[:2] == ["INTRODUCTION", "INTRODUCTION"], (conn, names[:4])
        assert "updateNumbers" in names, conn

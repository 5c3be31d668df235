"""Hostile map servers: a ``getMap`` or ``getMapBinary`` reply that never ends.

The header is a normal one; then point lines (text) or 1000-point blocks (binary) follow for as
long as the client stays connected, written as fast as the socket takes them. Used by the map-bound
tests and by ``bench/bench_mapdownload.py``.
"""

from __future__ import annotations

import asyncio
import contextlib
import time

from rtmu.protocol.fields import FieldWriter
from rtmu.protocol.payloads.map import MapId

from .servers import MAP_LINES, SPECS, ServerSide, TestServer

HEADER = MAP_LINES[: MAP_LINES.index("LINES")]
BATCH = 2000
"""Packets queued per socket write: big enough to outrun any client, small enough to stop quickly."""


MAP_ID_SPEC = ("getMapId", "map id", "none", "source name checksum size time", "Map", "RETURN_SINGLE")


def map_id_server(specs: list[tuple[str, str, str, str, str, str]] | None = None) -> TestServer:
    """A test server that also answers ``getMapId``; ``server.map_checksum`` is its map's MD5."""
    server = TestServer([*(SPECS if specs is None else specs), MAP_ID_SPEC])
    server.map_checksum = bytes(range(16))  # type: ignore[attr-defined]
    server.handlers["getMapId"] = lambda side, args: [
        MapId("", "test.map", server.map_checksum, 1234, 1_700_000_000).encode()  # type: ignore[attr-defined]
    ]
    return server


def endless_map_server(kind: str, claim: int | None = None) -> TestServer:
    """A server whose map (``kind`` "text": only ``getMap``; "binary": ``getMapBinary``) never ends.

    ``claim``: the header's ``NumPoints`` (a liar's huge count); by default the header is honest
    about its first 2 points and the stream simply goes on."""
    if kind not in ("text", "binary"):
        raise ValueError(kind)
    drop = "getMapBinary" if kind == "text" else "getMap"
    server = map_id_server([s for s in SPECS if s[0] != drop])
    server.map_requests = 0  # type: ignore[attr-defined]

    def stream(side: ServerSide, args: bytes) -> None:
        server.map_requests += 1  # type: ignore[attr-defined]
        name = "getMap" if kind == "text" else "getMapBinary"
        asyncio.get_running_loop().create_task(_forever(side, name, kind, claim))

    server.handlers["getMap" if kind == "text" else "getMapBinary"] = stream  # type: ignore[assignment]
    return server


async def _forever(side: ServerSide, name: str, kind: str, claim: int | None) -> None:
    conn, writer = side.conn, side.writer
    header = [
        f"NumPoints: {claim}" if claim is not None and x.startswith("NumPoints:") else x for x in HEADER
    ]
    for line in header:
        conn.send_data(name, FieldWriter().string(line).bytes())
    conn.send_data(name, FieldWriter().string("DATA").bytes())
    writer.write(conn.data_to_send())
    # One batch framed once, then written again and again: the server must outrun the client.
    if kind == "binary":
        block = FieldWriter().byte4(1000)
        for i in range(1000):
            block.byte4(i).byte4(-i)
        for _ in range(BATCH // 20):
            conn.send_data(name, block.bytes())
    else:
        for n in range(BATCH):
            conn.send_data(name, FieldWriter().string(f"{n} {n % 5000}").bytes())
    batch = conn.data_to_send()
    with contextlib.suppress(ConnectionError, RuntimeError, asyncio.CancelledError):
        while not writer.is_closing():
            writer.write(batch)
            await writer.drain()


def run_watching_peak(argv: list[str], poll: float = 0.005) -> tuple[int, float, str]:
    """Run ``argv``; its exit code, peak resident MB and stderr.

    The peak is the kernel's ``VmHWM`` of the program itself, read until it exits. Why not
    ``ru_maxrss`` from ``wait4``: for a child forked from a big process (pytest, the bench) Linux
    keeps the high-water mark from before ``exec``, so every figure would read as the parent's size.
    """
    import subprocess
    import threading

    proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    err: list[str] = []
    reader = threading.Thread(target=lambda: err.append(proc.stderr.read()), daemon=True)  # type: ignore[union-attr]
    reader.start()
    peak_kb = 0
    try:
        while proc.poll() is None:
            try:
                with open(f"/proc/{proc.pid}/status") as f:
                    for line in f:
                        if line.startswith("VmHWM:"):
                            peak_kb = max(peak_kb, int(line.split()[1]))
            except (OSError, ValueError):
                pass
            time.sleep(poll)
        proc.wait()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    reader.join(5)
    return proc.returncode, peak_kb / 1024, "".join(err)

"""Bytes off the wire: typed status in bulk, and the text map (``getMap``), in CPU time.

CPU time (``time.process_time``, the measured process alone), not wall time: the figures must hold
on a loaded machine. Each figure is the best of :data:`RUNS`, the baseline measured in the same run.

* ``wire.typed_status_packets_per_cpu_s``: 100 000 ``updateNumbers`` packets, read in the chunk
  sizes a TCP reader gets (``bench_codec``'s), to typed values through
  :class:`~rtmu.protocol.status_batch.StatusStream`. Baseline: today's per-packet path, the
  :class:`~rtmu.protocol.decoder.PacketDecoder` and ``UpdateNumbers.decode`` (the same values: checked).
  Target ≥ 1 M packets per CPU-second.
* ``wire.typed_status_aria_stream_packets_per_cpu_s``: the same on the status stream ARIA's own
  ``ArNetPacket`` writes (``cppdecode gen-status``: 100 000 ``update`` packets, 41 bytes), where
  ``/work/realpeer/cppdecode`` is built. Baseline: ``cppdecode decode`` — ARIA's framing and
  checksum in C++, no typed fields — in packets per second of its own timing.
* ``wire.getmap_text_us_per_packet``: ``download_map`` of a 200 000-point map over ``getMap`` (the
  text map, for servers older than ARIA 2.7) from ``rtmu sim`` in its own process: the client's CPU
  per packet, conversion to a map included. Baseline: the same script on the tree before this work
  (:data:`BEFORE`, taken with ``git archive``; no baseline where that commit is not in the repository).
  Target: half the baseline or less.
* ``wire.getmap_text_vs_aria_us_per_packet``: the same figure; baseline ARIA's ``mapClient`` (where
  built) fetching the same map from the same simulator: its CPU per line, from start until it has
  written the map (start-up, ``ArMap`` parsing and the file included).
"""

from __future__ import annotations

import contextlib
import os
import random
import re
import subprocess
import sys
import tarfile
import tempfile
import time
from collections.abc import Iterator
from io import BytesIO
from pathlib import Path

from bench.bench_codec import READ_SIZES, UPDATE_NUMBERS, status_packets
from bench.common import Result, as_installed, cache_bytecode, cpu_seconds, end_process
from rtmu.protocol import PacketDecoder
from rtmu.protocol.payloads.robot import Update, UpdateNumbers
from rtmu.protocol.status_batch import StatusBatch, StatusStream

REPO = Path(__file__).resolve().parents[1]
RUNS = 3
STATUS_PACKETS = 100_000
MAP_POINTS = 200_000
MAP_LINES = 2_000
BEFORE = "cf6185b32b0e311ca0812d74275adecc0d18376a"
"""``integrate`` when this work started: today's path for the text map's baseline."""
REALPEER = Path("/work/realpeer")
CPPDECODE = REALPEER / "cppdecode"
MAPCLIENT = REALPEER / "aria" / "ArNetworking" / "tests" / "mapClient"
ARIA_LIB = REALPEER / "aria" / "lib"
ARIA_UPDATE = 0x0100
"""The command number ``cppdecode gen-status`` gives its status packets (an ``update`` layout)."""

_MAP_SCRIPT = """
import asyncio, sys, time
from rtmu.client.connection import AriaClient
from rtmu.client.mapload import download_map
try:  # (the baseline's tree predates Target: its connect took the host and port)
    from rtmu.values.target import Target
except ImportError:
    Target = None

async def main(port):
    client = AriaClient()
    await client.connect(*((Target("127.0.0.1", port),) if Target else ("127.0.0.1", port)))
    start = time.process_time()
    got = await download_map(client, prefer_binary=False, timeout=60)
    spent = time.process_time() - start
    await client.disconnect()
    print(spent, got.packets, got.source)

asyncio.run(main(int(sys.argv[1])))
"""


# -- typed status ---------------------------------------------------------------------------------


def _chunks(stream: bytes) -> list[bytes]:
    out, pos, sizes = [], 0, iter(READ_SIZES * (len(stream) // 1000 + 1))
    while pos < len(stream):
        size = next(sizes)
        out.append(stream[pos : pos + size])
        pos += size
    return out


def _per_packet(chunks: list[bytes], commands: dict[int, str]) -> list[UpdateNumbers | Update]:
    decoder = PacketDecoder()
    out: list[UpdateNumbers | Update] = []
    for chunk in chunks:
        for command, payload in decoder.feed(chunk):
            name = commands.get(command)
            if name == "updateNumbers":
                out.append(UpdateNumbers.decode(payload))
            elif name == "update":
                out.append(Update.decode(payload))
    return out


def _bulk(chunks: list[bytes], commands: dict[int, str]) -> list[StatusBatch]:
    stream = StatusStream(commands)
    out = [batch for chunk in chunks if (batch := stream.feed(chunk)) is not None]
    out.append(stream.close())
    return out


def _values(batches: list[StatusBatch], commands: dict[int, str]) -> list[UpdateNumbers | Update]:
    updates = {command for command, name in commands.items() if name == "update"}
    return [
        batch.update_at(i) if int(batch.command[i]) in updates else batch.numbers_at(i)
        for batch in batches
        for i in range(len(batch))
    ]


def _cpu(fn: object, *args: object) -> float:
    best = float("inf")
    for _ in range(RUNS):
        start = time.process_time()
        fn(*args)  # type: ignore[operator]
        best = min(best, time.process_time() - start)
    return best


def _typed_status() -> list[Result]:
    commands = {UPDATE_NUMBERS: "updateNumbers"}
    packets = status_packets(random.Random(2), STATUS_PACKETS)
    chunks = _chunks(b"".join(packets))
    if _values(_bulk(chunks, commands), commands) != _per_packet(chunks, commands):
        raise RuntimeError("the bulk status decode differs from the per-packet one")
    bulk = _cpu(_bulk, chunks, commands)
    each = _cpu(_per_packet, chunks, commands)
    rate, baseline = len(packets) / bulk, len(packets) / each
    out = [Result("wire.typed_status_packets_per_cpu_s", rate, "packets/s", baseline)]
    if CPPDECODE.exists():
        out.append(_aria_stream())
    return out


def _aria_stream() -> Result:
    env = dict(os.environ, LD_LIBRARY_PATH=str(ARIA_LIB))
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "status.bin"
        subprocess.run([str(CPPDECODE), "gen-status", str(path)], env=env, check=True, capture_output=True)
        said = subprocess.run(
            [str(CPPDECODE), "decode", str(path)], env=env, check=True, capture_output=True, text=True
        )
        aria = float(re.search(r"([\d.]+) packets/s", said.stdout).group(1))  # type: ignore[union-attr]
        data = path.read_bytes()
    commands = {ARIA_UPDATE: "update"}
    chunks = _chunks(data)
    got = _values(_bulk(chunks, commands), commands)
    if not got or got != _per_packet(chunks, commands):
        raise RuntimeError("ARIA's status stream decodes differently in bulk")
    return Result("wire.typed_status_aria_stream_packets_per_cpu_s", len(got) / _cpu(_bulk, chunks, commands),
                  "packets/s", aria)  # fmt: skip


# -- the text map ---------------------------------------------------------------------------------


@contextlib.contextmanager
def _simulator(map_path: Path) -> Iterator[int]:
    sim = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "sim", "--port", "0", "--map", str(map_path), "--no-camera"],
        stdout=subprocess.PIPE, text=True, env=as_installed(dict(os.environ)),
    )  # fmt: skip
    try:
        assert sim.stdout is not None
        line = sim.stdout.readline()
        found = re.search(r":(\d+),", line)
        if found is None:
            raise RuntimeError(f"the simulator did not say its port: {line!r}")
        yield int(found.group(1))
    finally:
        end_process(sim)


def _before_tree(into: Path) -> Path | None:
    """``src`` of :data:`BEFORE`, unpacked under ``into`` (None: not in this repository)."""
    done = subprocess.run(["git", "-C", str(REPO), "archive", BEFORE, "src"], capture_output=True)
    if done.returncode != 0:
        return None
    with tarfile.open(fileobj=BytesIO(done.stdout)) as tar:
        # (our own tree from git; the "data" filter where this Python has it — 3.11.4 and later)
        tar.extractall(into, **({"filter": "data"} if hasattr(tarfile, "data_filter") else {}))
    compile_all = [sys.executable, "-m", "compileall", "-q", str(into / "src")]
    subprocess.run(compile_all, check=False, stdout=subprocess.DEVNULL)
    return into / "src"


def _map_us(src: Path, port: int) -> float:
    env = as_installed(dict(os.environ, PYTHONPATH=str(src)))
    best = float("inf")
    for _ in range(RUNS):
        said = subprocess.run([sys.executable, "-c", _MAP_SCRIPT, str(port)], env=env, check=True,
                              capture_output=True, text=True).stdout.split()  # fmt: skip
        if said[2] != "getMap":
            raise RuntimeError(f"the map came over {said[2]}, not getMap")
        best = min(best, float(said[0]) / int(said[1]) * 1e6)
    return best


def _mapclient_us(port: int, lines: int) -> float | None:
    """ARIA's mapClient: CPU per line until it has written the map it fetched (it never exits)."""
    if not MAPCLIENT.exists():
        return None
    best = float("inf")
    env = dict(os.environ, LD_LIBRARY_PATH=str(ARIA_LIB))
    for _ in range(RUNS):
        with tempfile.TemporaryDirectory() as tmp:
            command = [str(MAPCLIENT), "-host", "127.0.0.1", "-port", str(port)]
            proc = subprocess.Popen(
                command, cwd=tmp, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
            )
            try:
                written, deadline, size = Path(tmp) / "mapExample.map", time.monotonic() + 120, -1
                while time.monotonic() < deadline:  # written, and no longer growing
                    time.sleep(0.05)
                    now = written.stat().st_size if written.exists() else -1
                    if now > 0 and now == size:
                        break
                    size = now
                else:
                    return None
                best = min(best, cpu_seconds(proc.pid) / lines * 1e6)
            finally:
                end_process(proc)
    return best


def _text_map() -> list[Result]:
    with tempfile.TemporaryDirectory() as tmp:
        map_path = Path(tmp) / "big.map"
        make = ["--make-map", str(map_path), "--points", str(MAP_POINTS), "--lines", str(MAP_LINES)]
        subprocess.run([sys.executable, "-m", "rtmu", "sim", *make], check=True, capture_output=True)
        lines = sum(1 for _ in map_path.open("rb"))
        before = _before_tree(Path(tmp) / "before")
        with _simulator(map_path) as port:
            now = _map_us(REPO / "src", port)
            then = _map_us(before, port) if before is not None else None
            aria = _mapclient_us(port, lines)
    out = [Result("wire.getmap_text_us_per_packet", now, "us", then)]
    if aria is not None:
        out.append(Result("wire.getmap_text_vs_aria_us_per_packet", now, "us", aria))
    return out


def run() -> list[Result]:
    cache_bytecode()
    return _typed_status() + _text_map()


if __name__ == "__main__":
    for r in run():
        print(f"{r.name:50s} {r.value:14.4g} {r.unit:10s} baseline={r.baseline}")

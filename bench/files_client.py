"""One file transfer against a running simulator, in a process of its own: ``python -m bench.files_client
MODE PORT REMOTE LOCAL`` prints ``{"seconds": …, "peak_mb": …}`` (the transfer's time; the process's
peak resident memory, ``VmHWM``).

Modes: ``get`` / ``put`` (RTMU's streaming download and upload), ``get-simple`` (the simple way: the
whole ``getFile`` reply collected in memory, then written at once), ``put-simple`` (the whole file read
into memory, then sent as plain ``putFile`` packets), ``put-interleaved`` (ARIA's packet-by-packet variant).
"""

from __future__ import annotations

import asyncio
import json
import sys
import time
from pathlib import Path

from rtmu.client.connection import AriaClient
from rtmu.client.download import download_file
from rtmu.client.upload import upload_file
from rtmu.protocol.payloads.files import (
    FILE_CHUNK,
    FileChunk,
    GetFileRequest,
    PutFileCommand,
    PutFileRequest,
)
from rtmu.values.target import Target


def peak_mb() -> float:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    return 0.0


async def get_simple(c: AriaClient, remote: str, local: Path) -> None:
    reply = await c.request_once(GetFileRequest(remote), timeout=30, max_packets=1 << 22, max_bytes=1 << 31)
    chunks = [FileChunk.decode(p) for p in reply.payloads]
    local.write_bytes(b"".join(ch.data for ch in chunks if not ch.end))


async def put_simple(c: AriaClient, remote: str, local: Path) -> None:
    data = local.read_bytes()
    done = asyncio.Event()
    c.listen("putFile", lambda packet: done.set())
    c.send(PutFileRequest(PutFileCommand.START, remote))
    for i in range(0, len(data), FILE_CHUNK):
        c.send(PutFileRequest(PutFileCommand.DATA, remote, data[i : i + FILE_CHUNK]))
        await c.drain(30)
    c.send(PutFileRequest(PutFileCommand.DONE, remote))
    await asyncio.wait_for(done.wait(), 30)


async def main(mode: str, port: int, remote: str, local: Path) -> None:
    c = AriaClient()
    await c.connect(Target("127.0.0.1", port), timeout=30)
    try:
        started = time.perf_counter()
        if mode == "get":
            await download_file(c, remote, local, overwrite=True, timeout=30)
        elif mode == "get-simple":
            await get_simple(c, remote, local)
        elif mode == "put":
            await upload_file(c, local, remote, timeout=30, interleaved=False)
        elif mode == "put-interleaved":
            await upload_file(c, local, remote, timeout=30, interleaved=True)
        elif mode == "put-simple":
            await put_simple(c, remote, local)
        else:
            raise SystemExit(f"unknown mode {mode}")
        seconds = time.perf_counter() - started
    finally:
        await c.disconnect()
    print(json.dumps({"seconds": seconds, "peak_mb": peak_mb()}))


if __name__ == "__main__":
    asyncio.run(main(sys.argv[1], int(sys.argv[2]), sys.argv[3], Path(sys.argv[4])))

"""Files on the robot: download and upload throughput of a 50 MB file, and the client's peak memory.

The simulator runs in a process of its own (``rtmu sim --files DIR``), each transfer in another
(``bench.files_client``), over loopback. Baselines, in the same run, are the simple ways: the whole
``getFile`` reply collected in memory and written at once; the whole file read into memory and sent.

- ``files.download_mb_per_s`` / ``files.download_peak_mb``: RTMU's streaming download (to a temporary
  file, renamed at the end) of the 50 MB file; baseline: the whole reply in memory.
- ``files.download_200mb_peak_mb``: the same download of a 200 MB file (memory must stay flat);
  baseline: the 50 MB one.
- ``files.upload_mb_per_s`` / ``files.upload_peak_mb``: plain ``putFile``, paced on the socket;
  baseline: the whole file in memory.
- ``files.upload_interleaved_mb_per_s``: ARIA's packet-by-packet variant (one round trip a packet);
  baseline: the plain upload.
"""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench.common import Result, end_process

MB = 1_000_000
SIZE = 50 * MB
BIG = 200 * MB


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _transfer(mode: str, port: int, remote: str, local: Path) -> tuple[float, float]:
    out = subprocess.run(
        [sys.executable, "-m", "bench.files_client", mode, str(port), remote, str(local)],
        capture_output=True, text=True, timeout=600, check=True,
    )  # fmt: skip
    doc = json.loads(out.stdout.strip().splitlines()[-1])
    return doc["seconds"], doc["peak_mb"]


def _wait_listening(port: int, proc: subprocess.Popen[bytes]) -> None:
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise RuntimeError("the simulator ended before listening")
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.1)
    raise RuntimeError("the simulator did not listen within 60 s")


def run() -> list[Result]:
    with tempfile.TemporaryDirectory(prefix="rtmu-bench-files-") as tmp:
        robot, here = Path(tmp) / "robot", Path(tmp) / "here"
        robot.mkdir()
        here.mkdir()
        block = os.urandom(MB)
        with (robot / "big.bin").open("wb") as f:
            for _ in range(SIZE // MB):
                f.write(block)
        with (robot / "huge.bin").open("wb") as f:
            for _ in range(BIG // MB):
                f.write(block)
        (here / "up.bin").write_bytes((robot / "big.bin").read_bytes())
        port = _free_port()
        sim = subprocess.Popen(
            [sys.executable, "-m", "rtmu", "sim", "--port", str(port), "--no-map", "--no-camera",
             "--files", str(robot)],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        try:
            _wait_listening(port, sim)
            get_s, get_peak = _transfer("get", port, "big.bin", here / "got.bin")
            simple_s, simple_peak = _transfer("get-simple", port, "big.bin", here / "simple.bin")
            _huge_s, huge_peak = _transfer("get", port, "huge.bin", here / "huge.bin")
            (here / "huge.bin").unlink()
            put_s, put_peak = _transfer("put", port, "up1.bin", here / "up.bin")
            put_simple_s, put_simple_peak = _transfer("put-simple", port, "up2.bin", here / "up.bin")
            inter_s, _ = _transfer("put-interleaved", port, "up3.bin", here / "up.bin")
            same = (
                (robot / "up1.bin").read_bytes()
                == (here / "got.bin").read_bytes()
                == (robot / "big.bin").read_bytes()
            )
            if not same:
                raise RuntimeError("a transfer did not arrive whole")
        finally:
            end_process(sim)
    size_mb = SIZE / MB
    return [
        Result("files.download_mb_per_s", size_mb / get_s, "MB/s", size_mb / simple_s),
        Result("files.download_peak_mb", get_peak, "MB", simple_peak),
        Result("files.download_200mb_peak_mb", huge_peak, "MB", get_peak),
        Result("files.upload_mb_per_s", size_mb / put_s, "MB/s", size_mb / put_simple_s),
        Result("files.upload_peak_mb", put_peak, "MB", put_simple_peak),
        Result("files.upload_interleaved_mb_per_s", size_mb / inter_s, "MB/s", size_mb / put_s),
    ]

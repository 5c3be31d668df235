"""What ARIA's central server costs an operator: status latency through a forwarder vs direct.

The same simulated robot configuration is reached two ways in one run: directly (the baseline) and
through ``rtmu sim --central`` (the robot switched to the central server; the operator dials the
port the central server forwards it on, and every request and reply makes one more hop through the
forwarder). Each server is an ``rtmu sim`` process of its own, as deployed. Each sample is one
``updateNumbers`` request answered; the two connections take turns, so load on a shared machine falls
on both alike. Also timed: one ``list_robots`` (login to the central
server, ``clientList``, logout) with three robots.
"""

from __future__ import annotations

import asyncio
import re
import statistics
import subprocess
import sys
import time

from rtmu.client.central import list_robots
from rtmu.client.connection import AriaClient
from rtmu.values.target import Target

from .common import Result, end_process

SAMPLES = 1000
WARMUP = 20


async def _latencies(*ports: int) -> list[list[float]]:
    """Milliseconds per answered ``updateNumbers`` on each port, the ports taking turns sample by sample
    (so a burst of load on the shared machine falls on both alike)."""
    clients = [AriaClient() for _ in ports]
    for client, port in zip(clients, ports, strict=True):
        await client.connect(Target("127.0.0.1", port), timeout=10)
    try:
        out: list[list[float]] = [[] for _ in ports]
        for i in range(WARMUP + SAMPLES):
            for client, times in zip(clients, out, strict=True):
                t0 = time.perf_counter()
                await client.request_once("updateNumbers", timeout=10)
                if i >= WARMUP:
                    times.append((time.perf_counter() - t0) * 1000.0)
        return out
    finally:
        for client in clients:
            await client.disconnect()


def _p95(values: list[float]) -> float:
    return statistics.quantiles(values, n=20)[-1]


async def _list_ms(port: int, rounds: int = 20) -> float:
    best = float("inf")
    for _ in range(rounds):
        t0 = time.perf_counter()
        robots = await list_robots("127.0.0.1", port, timeout=10)
        best = min(best, (time.perf_counter() - t0) * 1000.0)
        assert len(robots) == 3
    return best


def _start(*argv: str) -> tuple[subprocess.Popen[str], str]:
    """``rtmu sim ARGV`` in its own process; returns it and its first line (which names its ports)."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "rtmu", "sim", "--port", "0", "--no-camera", *argv],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    assert proc.stdout is not None
    return proc, proc.stdout.readline()


def _port_after(text: str, marker: str) -> int:
    return int(re.search(re.escape(marker) + r"127\.0\.0\.1:(\d+)", text).group(1))  # type: ignore[union-attr]


async def _wait_listed(port: int, count: int) -> list[int]:
    deadline = time.monotonic() + 60
    while True:
        robots = await list_robots("127.0.0.1", port, timeout=10)
        if len(robots) == count:
            return [e.port for e, _ in robots]
        if time.monotonic() > deadline:
            raise TimeoutError(f"{len(robots)} robots switched, not {count}")
        await asyncio.sleep(0.1)


def run() -> list[Result]:
    procs: list[subprocess.Popen[str]] = []
    try:
        # Every server in a process of its own, as deployed: the client here shares no GIL with them.
        direct, line = _start()
        procs.append(direct)
        direct_port = _port_after(line, "listening on ")
        central, line = _start("--central", "--robot-port", "0", "--robots", "0")
        procs.append(central)
        central_port = _port_after(line, "operators on ")
        robot_port = _port_after(line, "robots switch to ")
        robot, _ = _start("--switch-to", f"127.0.0.1:{robot_port}", "--name", "robot1")
        procs.append(robot)
        (forwarded_port,) = asyncio.run(_wait_listed(central_port, 1))
        base, forwarded = asyncio.run(_latencies(direct_port, forwarded_port))
        for i in (2, 3):
            more, _ = _start("--switch-to", f"127.0.0.1:{robot_port}", "--name", f"robot{i}")
            procs.append(more)
        asyncio.run(_wait_listed(central_port, 3))
        listing = asyncio.run(_list_ms(central_port))
    finally:
        for proc in reversed(procs):
            end_process(proc)
    return [
        Result("central.status_latency_p50_ms", statistics.median(forwarded), "ms", statistics.median(base)),
        Result("central.status_latency_p95_ms", _p95(forwarded), "ms", _p95(base)),
        Result("central.list_robots_ms", listing, "ms"),
    ]


if __name__ == "__main__":
    for r in run():
        print(r.as_json())

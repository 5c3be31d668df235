"""What ARIA's central server costs an operator: status latency through a forwarder vs direct.

The same simulated robot configuration is reached two ways in one run: directly (the baseline) and
through ``rtmu sim --central`` (the robot switched to the central server; the operator dials the
port the central server forwards it on, and every request and reply makes one more hop through the
forwarder; the central server and that one robot share a thread here). Each sample is one
``updateNumbers`` request answered; servers run on threads of this process, so the figures include
their share of the GIL on a loaded machine. Also timed: one ``list_robots`` (login to the central
server, ``clientList``, logout) with three robots.
"""

from __future__ import annotations

import asyncio
import statistics
import time

from rtmu.client.central import list_robots
from rtmu.client.connection import AriaClient
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.central_thread import CentralThread

from .common import Result

SAMPLES = 300
WARMUP = 20


async def _latencies(port: int) -> list[float]:
    client = AriaClient()
    await client.connect("127.0.0.1", port, timeout=10)
    try:
        out: list[float] = []
        for i in range(WARMUP + SAMPLES):
            t0 = time.perf_counter()
            await client.request_once("updateNumbers", timeout=10)
            if i >= WARMUP:
                out.append((time.perf_counter() - t0) * 1000.0)
        return out
    finally:
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


def run() -> list[Result]:
    template = SimConfig(port=0, camera=False)
    with SimThread(SimConfig(port=0, camera=False)) as direct:
        base = asyncio.run(_latencies(direct.port))
    with CentralThread(robots=1, template=template) as fleet:
        # One robot, as direct: the central server and the robot share one loop, as the direct robot
        # shares its loop with nobody else — the difference is the forwarder's hop alone.
        forwarded = asyncio.run(_latencies(fleet.robots()["robot1"]))
    with CentralThread(robots=3, template=template) as fleet:
        listing = asyncio.run(_list_ms(fleet.port))
    return [
        Result("central.status_latency_p50_ms", statistics.median(forwarded), "ms", statistics.median(base)),
        Result("central.status_latency_p95_ms", _p95(forwarded), "ms", _p95(base)),
        Result("central.list_robots_ms", listing, "ms"),
    ]


if __name__ == "__main__":
    for r in run():
        print(r.as_json())

"""What the details strings and the camera head cost.

* ``ptz.strings_update_us.hostile``: one ``getStrings`` packet of 10 000 values handled by the
  session's strings feed while the details table is open — decoded, paired with 10 000 labels and
  bounded to the 200 rows the table keeps. Baseline: the simulator's own 7-item packet.
* ``ptz.strings_kept_items.hostile``: rows the model holds after that packet (the bound, not the flood).
* ``ptz.move_to_position_ms``: from ``setCameraRel`` (10°) sent to the head read back where it was
  sent (``getCameraData`` asked again and again) against the real-time simulator over loopback, whose
  head turns at the VC-C4's 90°/s, median of 10 moves. Baseline: a bare ``getCameraData`` round trip.
* ``ptz.move_settled_ms``: from the same move to the feed calling it settled (``moving`` false: two
  readings 250 ms apart agree, and a VC-C4 could have turned that far) — when the window's label
  stops saying "moving". Baseline: ``ptz.move_to_position_ms`` (the price of being sure it stopped).
"""

from __future__ import annotations

import asyncio
import statistics
import time

from bench.common import Result, best_time
from rtmu.client.call_values import Packet
from rtmu.client.connection import AriaClient
from rtmu.client.detached import DetachedContext
from rtmu.client.ptz import PtzFeed
from rtmu.client.server_strings import StringsFeed
from rtmu.package_data import project_map
from rtmu.protocol.payloads.strings import StringItem, Strings, StringsInfo
from rtmu.sim import SimConfig, SimThread
from rtmu.sim.handlers import STRING_ITEMS
from rtmu.values.target import Target

OFFICE = project_map("office.map")
MOVES = 10


def _feed(labels: tuple[str, ...]) -> tuple[StringsFeed, DetachedContext]:
    ctx = DetachedContext()
    feed = StringsFeed(ctx)
    feed._set_info(StringsInfo(tuple(StringItem(label, 10) for label in labels)))  # as read after login
    feed.watching = True
    return feed, ctx


def strings_update() -> list[Result]:
    hostile_labels = tuple(f"x{i}" for i in range(10_000))
    hostile, kept = _feed(hostile_labels)
    flood = Packet("getStrings", Strings(tuple("v" for _ in hostile_labels)).encode(), 0.0)
    sim_labels = tuple(label for label, _ in STRING_ITEMS)
    plain, _ = _feed(sim_labels)
    ordinary = Packet("getStrings", Strings(tuple("12" for _ in sim_labels)).encode(), 0.0)
    hostile_s = best_time(lambda: hostile._on_values(flood))
    plain_s = best_time(lambda: plain._on_values(ordinary))
    return [
        Result("ptz.strings_update_us.hostile", hostile_s * 1e6, "us", plain_s * 1e6),
        Result("ptz.strings_kept_items.hostile", float(len(kept.robot.server_strings)), "items"),
    ]


async def _moves(port: int) -> tuple[float, float, float]:
    client = AriaClient()
    await client.connect(Target("127.0.0.1", port), timeout=10)
    try:
        feed = PtzFeed(DetachedContext(client))
        await feed.read_head(client)
        name = "getCameraDataCam1"
        bare: list[float] = []
        moved: list[float] = []
        settled: list[float] = []
        for i in range(MOVES):
            t0 = time.perf_counter()
            await client.request_once(name)
            bare.append(time.perf_counter() - t0)
            await feed.wait_settled()
            before = feed.state.position
            assert before is not None
            step = 10.0 if i % 2 == 0 else -10.0
            target = (before[0] + step, before[1], before[2])
            t0 = time.perf_counter()
            feed.move_rel(step, 0.0)
            while await feed.refresh() != target:  # the head turns at 90°/s: readings on the way
                pass
            moved.append(time.perf_counter() - t0)
            await feed.wait_settled()
            settled.append(time.perf_counter() - t0)
        return statistics.median(moved), statistics.median(bare), statistics.median(settled)
    finally:
        await client.disconnect()


def move_to_position() -> list[Result]:
    with SimThread(SimConfig(port=0, map_path=OFFICE)) as sim:
        moved, bare, settled = asyncio.run(_moves(sim.port))
    return [
        Result("ptz.move_to_position_ms", moved * 1000, "ms", bare * 1000),
        Result("ptz.move_settled_ms", settled * 1000, "ms", moved * 1000),
    ]


def run() -> list[Result]:
    return [*strings_update(), *move_to_position()]


if __name__ == "__main__":
    for r in run():
        base = f"  (baseline {r.baseline:.3f})" if r.baseline is not None else ""
        print(f"{r.name:40s} {r.value:10.3f} {r.unit}{base}")

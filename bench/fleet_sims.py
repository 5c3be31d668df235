"""The simulators of ``bench_fleet``, in their own process: N robots on the office map, all wandering.

``python -m bench.fleet_sims N [--still]`` prints one line ``PORTS p1 p2 …`` when every server
listens, then serves until SIGTERM. Wandering keeps every pose changing, so each status is news to
draw. ``--still`` robots stand (their status still comes at its rate): N wandering robots in one
Python process keep a core busy casting rays, so a benchmark of the window's own start-up and logins
would otherwise time the simulators — real robots' servers do not run on the operator's CPU.
"""

from __future__ import annotations

import asyncio
import contextlib
import signal
import sys

from rtmu.package_data import project_map
from rtmu.sim import SimConfig
from rtmu.sim.multi import SimFleet, fleet_configs

OFFICE = project_map("office.map")


async def main(count: int, wander: bool = True) -> None:
    fleet = SimFleet(fleet_configs(SimConfig(port=0, map_path=OFFICE, camera=False), count))
    await fleet.start()
    for server in fleet.servers if wander else ():
        server.world.wander()
    print("PORTS " + " ".join(str(s.port) for s in fleet.servers), flush=True)
    stop = asyncio.Event()
    loop = asyncio.get_running_loop()
    for sig in (signal.SIGINT, signal.SIGTERM):
        with contextlib.suppress(NotImplementedError, RuntimeError):
            loop.add_signal_handler(sig, stop.set)
    await stop.wait()
    await fleet.stop()


if __name__ == "__main__":
    asyncio.run(main(int(sys.argv[1]), wander="--still" not in sys.argv[2:]))

"""The simulator for the soak, in its own process, reporting when drive packets reach it.

``python -m bench.soak_server`` starts the real simulator (our office map, camera off) on a free
loopback port, prints ``port N`` and then one line per drive packet it receives:
``drive T TRANS ROT`` or ``stop T``, where ``T`` is ``time.monotonic()`` at the moment the packet
was decoded. CLOCK_MONOTONIC is one clock for every process on the machine, so the soak (another
process) compares it with its own release times. It runs in its own process so that the server's
work never competes with the client for one interpreter lock, as on a real robot.
"""

from __future__ import annotations

import sys
import time

from rtmu.package_data import project_map
from rtmu.protocol.payloads.drive import RatioDrive
from rtmu.sim.config import SimConfig
from rtmu.sim.server import SimServer
from rtmu.sim.thread import SimThread


def _tap(server_cls: type[SimServer]) -> None:
    """Print every ratioDrive and stop as it is handled (a bench-only wrapper of ``invoke``)."""
    original = server_cls.invoke

    def invoke(self, session, number, name, args, *, once):  # type: ignore[no-untyped-def]
        now = time.monotonic()
        if name == "ratioDrive":
            r = RatioDrive.decode(args)
            print(f"drive {now:.6f} {r.trans:g} {r.rot:g}", flush=True)
        elif name == "stop":
            print(f"stop {now:.6f}", flush=True)
        return original(self, session, number, name, args, once=once)

    server_cls.invoke = invoke  # type: ignore[method-assign]


def main() -> int:
    _tap(SimServer)
    office = project_map("office.map")
    sim = SimThread(SimConfig(port=0, map_path=office, camera=False)).start()
    assert sim.server is not None
    print(f"port {sim.server.port}", flush=True)
    try:
        sys.stdin.read()  # until the soak closes our stdin
    finally:
        sim.stop()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

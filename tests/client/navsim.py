"""A simulator that navigates faster than the wall clock, for tests of navigation over loopback.

The simulator runs on its manual clock and a thread moves it on :data:`STEP` s of simulated time
every :data:`PAUSE` s of real time (about five times real speed when the CPU keeps up), so a goal that
takes the simulated P3-DX 15 s is reached in a couple of seconds while everything else — sockets,
subscriptions, the client's own timeouts — stays real.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from rtmu.package_data import project_map
from rtmu.sim import SimThread
from simulators import running

OFFICE = project_map("office.map")
STEP = 0.05
PAUSE = 0.01


class FastClock:
    def __init__(self, sim: SimThread) -> None:
        self.sim = sim
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="sim-fast-clock", daemon=True)

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                self.sim.advance(STEP)
            except Exception:  # the simulator is closing
                return
            self._stop.wait(PAUSE)

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(10)


@contextmanager
def fast_sim(map_path: Path = OFFICE, **config: object) -> Iterator[SimThread]:
    """``with fast_sim() as sim:`` an office-map simulator whose clock runs fast."""
    with running(realtime=False, map_path=map_path, **config) as sim:
        clock = FastClock(sim)
        clock.start()
        try:
            yield sim
        finally:
            clock.stop()


def robot(sim: SimThread):  # type: ignore[no-untyped-def]
    """The simulator's robot, read on its own loop (status, mode_name, x, y …)."""
    return sim.snapshot()


def reset(sim: SimThread) -> None:
    """Stopped at home, localized: every test starts from the same place."""
    assert sim.server is not None
    server = sim.server

    def go() -> None:
        server.reset_pose()
        server.world.localize_to(*server.world.home[:2], server.world.home[2] or 0.0)

    sim.call(go)

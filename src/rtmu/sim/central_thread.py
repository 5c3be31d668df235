"""A central server and robots switched to it, on one thread and loop: for tests and ``bench``.

``with CentralThread(robots=3) as fleet: fleet.port`` is the central server's operator port; the robots
(``robot1``…) are real :class:`SimServer` s that switched to it over loopback, each forwarded on a port
of its own. Robots can be added, stopped or killed, and the central server killed, while operators are
connected.
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import Any

from .central import CentralConfig, CentralServer
from .config import SimConfig
from .loop_thread import LoopThread
from .server import SimServer


class CentralThread(LoopThread):
    what = "the central server"
    thread_name = "rtmu-central-sim"

    def __init__(
        self,
        robots: int = 3,
        template: SimConfig | None = None,
        *,
        switch_retry: float = 0.2,
        users_path: Path | None = None,
    ) -> None:
        super().__init__()
        self.template = template or SimConfig(port=0, camera=False)
        self.switch_retry = switch_retry
        self.users_path = users_path
        """The central server's user file (its port and the forwarders)."""
        self.initial = robots
        self.central: CentralServer | None = None
        self.sims: dict[str, SimServer] = {}

    async def _open(self) -> None:
        config = CentralConfig(host="127.0.0.1", port=0, robot_port=0, users_path=self.users_path)
        self.central = CentralServer(config)
        await self.central.start()

    # -- lifetime -------------------------------------------------------------------------
    def start(self) -> CentralThread:
        self._start_loop()
        for i in range(1, self.initial + 1):
            self.add_robot(f"robot{i}")
        self.wait_for_robots(self.initial)
        return self

    def stop(self) -> None:
        if not self.running:
            return

        async def stop_all() -> None:
            for sim in list(self.sims.values()):
                await sim.stop()
            if self.central is not None:
                await self.central.stop()

        self.run(stop_all())
        self._halt()

    def __enter__(self) -> CentralThread:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    # -- access ---------------------------------------------------------------------------
    @property
    def port(self) -> int:
        assert self.central is not None
        return self.central.port

    def robots(self) -> dict[str, int]:
        """Robot name → forwarded port, as the central server lists them now."""
        assert self.central is not None
        central = self.central
        return self.call(lambda: {e.name: e.port for e in central.robots()})

    def wait_for_robots(self, count: int, timeout: float = 20.0) -> dict[str, int]:
        deadline = time.monotonic() + timeout
        while True:
            robots = self.robots()
            if len(robots) == count:
                return robots
            if time.monotonic() > deadline:
                raise TimeoutError(f"{len(robots)} robots switched, not {count}: {sorted(robots)}")
            time.sleep(0.05)

    def add_robot(self, name: str, **changes: Any) -> SimServer:
        """Start a simulated robot that switches to the central server as ``name``."""
        assert self.central is not None
        cfg = dataclasses.replace(
            self.template,
            port=0,
            switch_to=f"127.0.0.1:{self.central.robot_port}",
            switch_name=name,
            switch_retry=self.switch_retry,
            central_server=None,
            **changes,
        )

        async def start() -> SimServer:
            sim = SimServer(cfg)
            await sim.start()
            return sim

        sim = self.run(start())
        self.sims[name] = sim
        return sim

    def stop_robot(self, name: str) -> None:
        """The robot's server stops cleanly (its switched connection gets SHUTDOWN)."""
        self.run(self.sims.pop(name).stop())

    def restart_central(self) -> None:
        """A new central server on the dead one's two ports (after :meth:`kill_central`), as a
        restarted process would be; the robots' switch retries find it on their own."""
        old = self.central
        assert old is not None

        async def start() -> None:
            config = CentralConfig(
                host="127.0.0.1", port=old.port, robot_port=old.robot_port, users_path=self.users_path
            )
            central = CentralServer(config)
            await central.start()
            self.central = central

        self.run(start())

    def kill_central(self) -> None:
        """The central server dies: every operator and robot socket reset at once."""
        assert self.central is not None
        self.call(self.central.kill)

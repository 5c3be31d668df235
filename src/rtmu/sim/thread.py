"""A simulator on its own thread and event loop: for synchronous tests, GUI tests and ``rtmu --demo``."""

from __future__ import annotations

from .config import SimConfig
from .loop_thread import LoopThread
from .server import SimServer
from .world import RobotSnapshot


class SimThread(LoopThread):
    """``with SimThread(cfg) as sim: ... sim.port ...`` — the server runs until the block ends."""

    what = "the simulator"
    thread_name = "rtmu-sim"

    def __init__(self, config: SimConfig | None = None) -> None:
        super().__init__()
        self.config = config or SimConfig(port=0)
        self.server: SimServer | None = None

    async def _open(self) -> None:
        self.server = SimServer(self.config)
        await self.server.start()

    # -- lifetime -------------------------------------------------------------------------
    def start(self) -> SimThread:
        self._start_loop()
        return self

    def stop(self) -> None:
        """Close cleanly: clients get SHUTDOWN."""
        if not self.running or self.server is None:
            return
        self.run(self.server.stop())
        self._halt()

    def kill(self) -> None:
        """Die abruptly: every socket closed without SHUTDOWN (a lost link, as a client sees it)."""
        if not self.running or self.server is None:
            return
        self.call(self.server.kill)
        self._halt()

    def __enter__(self) -> SimThread:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    # -- access ---------------------------------------------------------------------------
    @property
    def port(self) -> int:
        assert self.server is not None, "start the simulator first"
        return self.server.port

    def snapshot(self) -> RobotSnapshot:
        """A copy of the robot's state."""
        assert self.server is not None
        return self.call(self.server.world.snapshot)

    def advance(self, seconds: float, timeout: float = 60.0) -> None:
        """Manual clock (``realtime=False``): step ``seconds`` of simulated time now."""
        assert self.server is not None
        self.run(self.server.advance(seconds), timeout)

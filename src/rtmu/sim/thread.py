"""A simulator on its own thread and event loop: for synchronous tests, GUI tests and ``rtmu --demo``."""

from __future__ import annotations

import asyncio
import concurrent.futures
import threading
from collections.abc import Callable
from typing import Any, TypeVar

from .config import SimConfig
from .server import SimServer
from .world import RobotSnapshot

T = TypeVar("T")
START_TIMEOUT = 30.0


class SimThread:
    """``with SimThread(cfg) as sim: ... sim.port ...`` — the server runs until the block ends."""

    def __init__(self, config: SimConfig | None = None) -> None:
        self.config = config or SimConfig(port=0)
        self.server: SimServer | None = None
        self.loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._ready = threading.Event()
        self._error: BaseException | None = None

    # -- lifetime -------------------------------------------------------------------------
    def start(self) -> SimThread:
        self._thread = threading.Thread(target=self._main, name="rtmu-sim", daemon=True)
        self._thread.start()
        if not self._ready.wait(START_TIMEOUT):
            raise TimeoutError("the simulator did not start")
        if self._error is not None:
            raise RuntimeError("the simulator failed to start") from self._error
        return self

    def _main(self) -> None:
        loop = asyncio.new_event_loop()
        self.loop = loop
        asyncio.set_event_loop(loop)
        try:
            self.server = SimServer(self.config)
            loop.run_until_complete(self.server.start())
        except BaseException as exc:  # reported to the starting thread
            self._error = exc
            self._ready.set()
            loop.close()
            return
        self._ready.set()
        try:
            loop.run_forever()
        finally:
            pending = [t for t in asyncio.all_tasks(loop) if not t.done()]
            for task in pending:
                task.cancel()
            if pending:
                loop.run_until_complete(asyncio.gather(*pending, return_exceptions=True))
            loop.close()

    def stop(self) -> None:
        """Close cleanly: clients get SHUTDOWN."""
        if self.loop is None or self.server is None or not self.loop.is_running():
            return
        with_timeout(asyncio.run_coroutine_threadsafe(self.server.stop(), self.loop), 10.0)
        self._halt()

    def kill(self) -> None:
        """Die abruptly: every socket closed without SHUTDOWN (a lost link, as a client sees it)."""
        if self.loop is None or self.server is None or not self.loop.is_running():
            return
        self.call(self.server.kill)
        self._halt()

    def _halt(self) -> None:
        assert self.loop is not None
        self.loop.call_soon_threadsafe(self.loop.stop)
        if self._thread is not None:
            self._thread.join(10.0)

    def __enter__(self) -> SimThread:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    # -- access ---------------------------------------------------------------------------
    @property
    def port(self) -> int:
        assert self.server is not None, "start the simulator first"
        return self.server.port

    def call(self, fn: Callable[[], T], timeout: float = 10.0) -> T:
        """Run ``fn`` on the simulator's loop and return its result (thread-safe access to the world)."""
        assert self.loop is not None
        future: concurrent.futures.Future[T] = concurrent.futures.Future()

        def run() -> None:
            try:
                future.set_result(fn())
            except BaseException as exc:
                future.set_exception(exc)

        self.loop.call_soon_threadsafe(run)
        return future.result(timeout)

    def snapshot(self) -> RobotSnapshot:
        """A copy of the robot's state."""
        assert self.server is not None
        return self.call(self.server.world.snapshot)

    def advance(self, seconds: float, timeout: float = 60.0) -> None:
        """Manual clock (``realtime=False``): step ``seconds`` of simulated time now."""
        assert self.loop is not None and self.server is not None
        with_timeout(asyncio.run_coroutine_threadsafe(self.server.advance(seconds), self.loop), timeout)


def with_timeout(future: concurrent.futures.Future[Any], timeout: float) -> Any:
    return future.result(timeout)

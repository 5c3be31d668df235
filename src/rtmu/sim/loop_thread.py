"""A server on its own thread and event loop, reachable from synchronous code.

:class:`~rtmu.sim.thread.SimThread` (one simulator) and
:class:`~rtmu.sim.central_thread.CentralThread` (a central server with robots) differ only in what
they open on the loop and how they stop it; starting, running, reaching into the loop and
halting are the same, and live here.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import threading
from collections.abc import Callable, Coroutine
from typing import Any, TypeVar

T = TypeVar("T")
START_TIMEOUT = 30.0
"""Seconds a starting thread waits for the loop's server to listen."""
JOIN_TIMEOUT = 10.0


class LoopThread:
    """Subclasses open their server(s) in :meth:`_open`; ``what`` names them in errors."""

    what = "the server"
    thread_name = "rtmu-loop"

    def __init__(self) -> None:
        self.loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._ready = threading.Event()
        self._error: BaseException | None = None

    async def _open(self) -> None:
        """Start listening (on the loop). An exception reaches :meth:`start`'s caller."""
        raise NotImplementedError

    # -- lifetime -------------------------------------------------------------------------
    def _start_loop(self) -> None:
        self._thread = threading.Thread(target=self._main, name=self.thread_name, daemon=True)
        self._thread.start()
        if not self._ready.wait(START_TIMEOUT):
            raise TimeoutError(f"{self.what} did not start")
        if self._error is not None:
            raise RuntimeError(f"{self.what} failed to start") from self._error

    def _main(self) -> None:
        loop = asyncio.new_event_loop()
        self.loop = loop
        asyncio.set_event_loop(loop)
        try:
            loop.run_until_complete(self._open())
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

    @property
    def running(self) -> bool:
        return self.loop is not None and self.loop.is_running()

    def _halt(self) -> None:
        """End the loop (its remaining tasks are cancelled) and wait for the thread."""
        assert self.loop is not None
        self.loop.call_soon_threadsafe(self.loop.stop)
        if self._thread is not None:
            self._thread.join(JOIN_TIMEOUT)

    # -- access ---------------------------------------------------------------------------
    def call(self, fn: Callable[[], T], timeout: float = 10.0) -> T:
        """Run ``fn`` on the loop and return its result (thread-safe access to what lives there)."""
        assert self.loop is not None
        future: concurrent.futures.Future[T] = concurrent.futures.Future()

        def run() -> None:
            try:
                future.set_result(fn())
            except BaseException as exc:
                future.set_exception(exc)

        self.loop.call_soon_threadsafe(run)
        return future.result(timeout)

    def run(self, coro: Coroutine[Any, Any, T], timeout: float = 10.0) -> T:
        """Run ``coro`` on the loop and return its result."""
        assert self.loop is not None
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(timeout)

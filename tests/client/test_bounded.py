"""Every wait in the client core has a bound: a stuck task or a slow step ends in a clear outcome."""

from __future__ import annotations

import asyncio
import threading

import pytest

from rtmu.client import mapload
from rtmu.client.connection import AriaClient
from rtmu.client.errors import ClientTimeout
from rtmu.client.lease import DriveLease
from rtmu.client.runner import ClientRunner
from rtmu.client.session import Session
from rtmu.values.target import Target

from .servers import TestServer, run


async def _stubborn(release: threading.Event, started: threading.Event | None = None) -> None:
    """A task that ignores cancellation until ``release`` is set (a misbehaving callback)."""
    if started is not None:
        started.set()
    while not release.is_set():
        try:
            await asyncio.sleep(0.01)
        except asyncio.CancelledError:
            continue


def test_step_gives_up_when_the_heart_does_not_run() -> None:
    async def go() -> None:
        session = Session(DriveLease(), lambda change: None)
        session.drive.ensure_heart = lambda: None  # type: ignore[method-assign]  # no heart at all
        with pytest.raises(ClientTimeout, match="heart"):
            await session.step(timeout=0.05)

    run(go())


def test_disconnect_returns_even_if_the_reader_will_not_end() -> None:
    release = threading.Event()

    async def go() -> None:
        server = TestServer()
        await server.start()
        client = AriaClient()
        await client.connect(Target("127.0.0.1", server.port), timeout=5)
        real = client._read_task
        assert real is not None
        real.cancel()
        await asyncio.wait({real})
        started = threading.Event()
        stubborn = asyncio.create_task(_stubborn(release, started))
        await asyncio.sleep(0)
        assert started.is_set()
        client._read_task = stubborn
        await asyncio.wait_for(client.disconnect(), 3)  # TimeoutError here = the old unbounded wait
        assert not stubborn.done()
        release.set()
        await stubborn
        await server.stop()

    run(go())


def test_the_network_thread_ends_even_if_a_task_ignores_its_cancel() -> None:
    release, started = threading.Event(), threading.Event()
    runner = ClientRunner().start()
    try:
        runner.submit(_stubborn, release, started)
        assert started.wait(3)  # running (a task cancelled before its first step would just end)
        runner.close(timeout=3)
        assert not runner._thread.is_alive()
    finally:
        release.set()


def test_a_map_conversion_that_hangs_is_a_timeout(monkeypatch: pytest.MonkeyPatch) -> None:
    release = threading.Event()

    def hangs(assembler: object) -> None:
        release.wait(10)

    monkeypatch.setattr(mapload, "assembled_map", hangs)

    async def go() -> None:
        server = TestServer()
        await server.start()
        client = AriaClient()
        await client.connect(Target("127.0.0.1", server.port), timeout=5)
        try:
            with pytest.raises(ClientTimeout, match="converting the map"):
                await mapload.download_map(client, convert_timeout=0.05)
        finally:
            release.set()
            await client.disconnect()
            await server.stop()

    run(go())

"""A status the kernel already holds is not silence: the link is judged on what *arrived*.

On a loaded laptop the client's loop may run 150–300 ms late; the status that came meanwhile sits
unread in the socket, and judging the link by what the loop has read called it stale (the load4
soak's false stops). Here the loop's thread is kept from running (``time.sleep`` on the loop: the
machine did not run us) while the real simulator goes on sending through a real proxy: the stale
verdict read-time judging gives is the pattern that used to stop, and ``judged_fault`` /
``catch_up`` must not give it; a muted link and a garbage flood must still be judged faults.
"""

from __future__ import annotations

import asyncio
import time
from collections.abc import Awaitable, Callable, Iterator
from typing import Any

import pytest

from linkfaults import TO_CLIENT, FaultProxy
from rtmu.client.connection import AriaClient
from rtmu.client.drive_guard import DriveGuard
from rtmu.package_data import project_map
from rtmu.sim import SimThread
from rtmu.values.target import Target
from simulators import simulator

from .servers import run

sim = simulator(map_path=project_map("arena.map"))

NOT_RUN = 0.7
"""Seconds the loop's thread is kept from running: longer than any stale limit (ceiling 0.45 s)."""


@pytest.fixture
def proxy(sim: SimThread) -> Iterator[FaultProxy]:
    with FaultProxy("127.0.0.1", sim.port) as p:
        yield p


def _guarded(port: int, body: Callable[[AriaClient, DriveGuard], Awaitable[Any]]) -> Any:
    async def go() -> Any:
        client = AriaClient()
        await client.connect(Target("127.0.0.1", port), timeout=10)
        guard = DriveGuard(client)
        guard.start()
        try:
            async with asyncio.timeout(10):  # status flows (the link is judged OK on read time)
                while guard.fault(client.clock()) is not None or guard.health.status_timing.samples < 5:
                    await asyncio.sleep(0.05)
            return await body(client, guard)
        finally:
            await guard.close()
            await client.disconnect()

    return run(go(), timeout=60)


def _not_run(seconds: float = NOT_RUN) -> None:
    """The machine does not run this loop for ``seconds`` (the simulator's thread goes on)."""
    time.sleep(seconds)


def test_status_unread_in_the_socket_is_not_silence(sim: SimThread, proxy: FaultProxy) -> None:
    async def body(client: AriaClient, guard: DriveGuard) -> tuple[str | None, int, str | None, int]:
        _not_run()
        now = client.clock()
        by_reads = guard.fault(now)  # what the link looked like judged on the reads alone
        unread = client.unread()
        judged = await guard.judged_fault(now)
        return by_reads, unread, judged, client.unread()

    by_reads, unread, judged, left = _guarded(proxy.port, body)
    assert by_reads is not None and "no status" in by_reads  # the pattern that used to stop
    assert unread > 0  # …while the statuses were in the kernel
    assert judged is None  # read first: the link is fine
    assert left < unread


def test_a_muted_link_is_still_judged_stale(sim: SimThread, proxy: FaultProxy) -> None:
    async def body(client: AriaClient, guard: DriveGuard) -> str | None:
        await asyncio.sleep(0.2)  # (whatever is in flight is read)
        proxy.mute(TO_CLIENT)
        _not_run()
        return await guard.judged_fault(client.clock())

    why = _guarded(proxy.port, body)
    assert why is not None and "no status" in why


def test_a_garbage_flood_cannot_hold_the_verdict_off(sim: SimThread, proxy: FaultProxy) -> None:
    """Bytes keep arriving, none a status: catching up is bounded, and the link is judged stale."""

    async def body(client: AriaClient, guard: DriveGuard) -> tuple[str | None, int]:
        proxy.garble(TO_CLIENT)
        await asyncio.sleep(0.1)
        _not_run()
        waiting = client.unread()
        return await guard.judged_fault(client.clock()), waiting

    why, waiting = _guarded(proxy.port, body)
    assert waiting > 0  # the garbage was there to read
    assert why is not None and "no status" in why


def test_nothing_unread_costs_no_round() -> None:
    """A client with no link has nothing to catch up on (and says so at once)."""

    async def go() -> int:
        return await AriaClient().catch_up()

    assert run(go()) == 0

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
import sys
import time
from collections.abc import Awaitable, Callable, Iterator
from typing import Any

import pytest

from linkfaults import TO_CLIENT, FaultProxy
from patience import PATIENCE
from rtmu.client.call_values import Reply
from rtmu.client.connection import AriaClient
from rtmu.client.drive_guard import DriveGuard
from rtmu.client.errors import ClientTimeout
from rtmu.client.health import ping_data
from rtmu.client.lease import DriveRatios
from rtmu.client.runner import ClientRunner
from rtmu.client.session import SessionConfig
from rtmu.model.observables import RobotModel
from rtmu.package_data import project_map
from rtmu.sim import SimThread
from rtmu.values.target import Target
from simulators import simulator

from .servers import run
from .uiqueue import UiQueue

sim = simulator(map_path=project_map("arena.map"))

NOT_RUN = 0.7
"""Seconds the loop's thread is kept from running: longer than any stale limit (ceiling 0.45 s)."""
PING_DEADLINE = 0.3
"""A ping's deadline in the ping tests: well under the time the loop is not run."""


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


def test_a_ping_answered_while_the_loop_was_not_run_is_answered(sim: SimThread, proxy: FaultProxy) -> None:
    """The ping's answer came while the loop was not run: its timer and the answer wake the loop
    together, and a plain request's timer wins (the pattern that used to count a ping failure and
    stop the robot); ``ask_in_time`` reads what arrived first. A muted link still times out."""

    async def late(call: Awaitable[Any]) -> Any:
        task = asyncio.ensure_future(call)
        await asyncio.sleep(0)  # one round: the request is written, its answer not yet read
        _not_run(NOT_RUN * PATIENCE)  # the answer arrives meanwhile; the deadline passes
        try:
            return await task
        except ClientTimeout as exc:
            return exc

    async def body(client: AriaClient, _guard: DriveGuard) -> tuple[Any, Any, Any]:
        name = ping_data(client.datalist)
        assert name is not None
        plain = await late(client.request_once(name, timeout=PING_DEADLINE))
        judged = await late(client.ask_in_time(name, PING_DEADLINE))
        proxy.mute(TO_CLIENT)
        muted = await late(client.ask_in_time(name, PING_DEADLINE))
        return plain, judged, muted

    plain, judged, muted = _guarded(proxy.port, body)
    assert isinstance(plain, ClientTimeout), plain  # judged by the timer alone: a failure
    assert isinstance(judged, Reply), judged  # read first: answered
    assert isinstance(muted, ClientTimeout), muted


def test_nothing_unread_costs_no_round() -> None:
    """A client with no link has nothing to catch up on (and says so at once)."""

    async def go() -> int:
        return await AriaClient().catch_up()

    assert run(go()) == 0


def _hold_through_a_late_loop(
    port: int, before: Callable[[], object], after: Callable[[], object]
) -> list[str]:
    """The window's core holds a drive (the test renews the lease as the UI's 10 Hz timer does);
    ``before()``, then its network loop is not run for :data:`NOT_RUN`, then ``after()`` while still
    held; the stops it sent."""
    model, ui = RobotModel(), UiQueue()
    runner = ClientRunner(model, post=ui.post, config=SessionConfig(fetch_map=False))
    stops: list[str] = []
    runner.on_stop = lambda reason, sent: stops.append(reason)
    runner.start()
    try:
        runner.connect(Target("127.0.0.1", port)).result(10)
        ui.wait_for(lambda: model.health.value.rtt_ms is not None, timeout=10)
        runner.lease.grant(DriveRatios(30, 0, 30))
        _renew_for(runner, ui, 1.0)
        assert stops == []  # driving
        session = runner.session
        assert session is not None
        late = LateHeart(session.clock)
        session.clock = late  # (read by the drive loop's heart at each beat)
        before()
        late.armed = True
        _renew_for(runner, ui, 1.5)
        after()
        return list(stops)
    finally:
        runner.lease.release()
        runner.close()


class LateHeart:
    """The session's clock, but the heart's first look after :attr:`armed` finds its thread not run
    for :data:`NOT_RUN` — as a loaded laptop runs a loop woken by its timer: ``select`` has returned
    (the socket was quiet then), the statuses land in the kernel before the heart's step runs."""

    def __init__(self, clock: Callable[[], float]) -> None:
        self.clock = clock
        self.armed = False

    def __call__(self) -> float:
        if self.armed and sys._getframe(1).f_code.co_name in ("_judged_now", "_heart"):
            self.armed = False
            _not_run()
        return self.clock()


def _renew_for(runner: ClientRunner, ui: UiQueue, seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        runner.lease.renew()
        ui.drain()
        time.sleep(0.04)


def test_a_held_drive_survives_a_network_loop_run_late(sim: SimThread, proxy: FaultProxy) -> None:
    """Statuses came while the loop was not run: the heart reads them and drives on (judged on the
    reads alone — "no status for 0.7 s" — it stopped)."""
    held: list[float] = []
    stops = _hold_through_a_late_loop(
        proxy.port, lambda: None, lambda: held.append(sim.snapshot().trans_ratio)
    )
    assert stops == [], stops
    assert held == [30]  # still driving at the end


def test_a_muted_link_still_stops_a_held_drive_run_late(sim: SimThread, proxy: FaultProxy) -> None:
    stops = _hold_through_a_late_loop(proxy.port, lambda: proxy.mute(TO_CLIENT), lambda: None)
    assert stops and "no status" in stops[0], stops

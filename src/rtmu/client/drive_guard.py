"""The command line's link watch while it drives: the window's health rules, without a window.

``rtmu drive`` must not drive blind. :class:`DriveGuard` subscribes to ``updateNumbers``
(the status stream is the link's heartbeat, as in the window's session) and pings the
server, feeding both into the same :class:`~rtmu.client.health.HealthMonitor` the window
uses. :meth:`DriveGuard.fault` says, in words, why driving must stop now — stale status,
an unanswered or too slow ping, or a lost connection — or None while the link is OK.

Status comes at 20 Hz and the ping is tighter than the window's (every :data:`PING_INTERVAL` s):
a script has no operator watching the link cell, and a server that stopped reading would never
hear its ``stop``. How late either may be is learned per link by the window's own rule
(:mod:`~rtmu.base.link_timing`): status is stale after 0.2 s on a steady link and at most
0.45 s on a jittery one; a ping must be answered within 0.4–:data:`MAX_RTT` s.
"""

from __future__ import annotations

import asyncio
import contextlib
import time

from ..base.exit_codes import EXIT_TIMEOUT
from ..protocol.errors import ProtocolError
from ..protocol.payloads.robot import Update, UpdateNumbers
from ..values.state import LinkLevel
from .call_values import Packet
from .connection import AriaClient
from .errors import ClientError, ClientTimeout
from .health import HealthMonitor, ping_data

STATUS_INTERVAL_MS = 50
STALE_INTERVALS = 4
"""The stale limit's floor, 200 ms without status: what a steady link gets (the limit learned for
a jittery one is higher, up to ``link_timing.STATUS_CEILING``)."""
PING_INTERVAL = 0.25
PING_FLOOR = 0.4
MAX_RTT = 0.5
"""A ping not answered within this many seconds counts as a link fault (round trip too high); the
deadline learned on a steady link is shorter, down to :data:`PING_FLOOR`."""


class LinkFault(ClientError):
    """Driving was stopped because the link went bad (exit 5, like a timeout)."""

    exit_code = EXIT_TIMEOUT
    kind = "link"


class DriveGuard:
    """Status subscription + pings → :meth:`fault`. Create after login; ``start()``; ``close()``."""

    def __init__(
        self, client: AriaClient, *, max_rtt: float = MAX_RTT, ping_interval: float = PING_INTERVAL
    ) -> None:
        self.client = client
        self.max_rtt = max_rtt
        self.ping_interval = ping_interval
        self.health = HealthMonitor(
            STATUS_INTERVAL_MS / 1000.0,
            stale_intervals=STALE_INTERVALS,
            ping_floor=PING_FLOOR,
            ping_ceiling=max_rtt,
        )
        self.changed = asyncio.Event()
        """Set whenever something arrives or fails that may change :meth:`fault` (a wake-up)."""
        self._ping_task: asyncio.Task[None] | None = None
        self._status_name = "updateNumbers" if client.supports("updateNumbers") else "update"
        self.seen_moving = False
        """A status since this was last cleared showed the robot moving (``rtmu drive``: did it move?)."""

    def start(self) -> None:
        """Subscribe to status at 10 Hz and start pinging; the status age counts from now."""
        self.health.start(self.client.clock())
        client = self.client
        self.health.bind(f"{client.host}:{client.port}", lambda: client.last_packet_at, client.undecided)
        if self.client.on_close is None:  # a lost connection wakes the drive loop at once
            self.client.on_close = lambda error: self.changed.set()
        self.client.request(self._status_name, STATUS_INTERVAL_MS, self._on_status)
        if ping_data(self.client.datalist) is not None:
            self._ping_task = asyncio.get_running_loop().create_task(self._ping_loop(), name="drive-ping")

    def _on_status(self, packet: Packet) -> None:
        self.health.note_status(packet.received_at)
        if not self.seen_moving:
            self.seen_moving = _shows_motion(packet)
        self.changed.set()

    async def _ping_loop(self) -> None:
        name = ping_data(self.client.datalist)
        assert name is not None
        while self.client.connected:
            started = time.perf_counter()
            try:
                await self.client.ask_in_time(name, self.health.ping_deadline(self.client.clock()))
            except ClientTimeout:
                self.health.note_ping_timeout()
                self.changed.set()
            except ClientError:
                self.changed.set()
                return
            else:
                self.health.note_rtt(time.perf_counter() - started, self.client.clock())
            await asyncio.sleep(self.ping_interval)

    def next_check(self, now: float) -> float:
        """When :meth:`fault` could next turn non-None without anything arriving."""
        return self.health.next_change(now)

    def fault(self, now: float) -> str | None:
        """Why driving must stop now (one sentence naming the fault), or None while the link is OK."""
        error = self.client.closed_error
        if error is not None:
            return f"lost the link: {error}"
        if self.health.level(now) is LinkLevel.OK:
            return None
        return self.health.cause(now)

    async def judged_fault(self, now: float) -> str | None:
        """:meth:`fault`, but silence is judged on what has *arrived*: status the kernel already
        holds, unread because the machine ran us late, is read first (``AriaClient.catch_up``)."""
        why = self.fault(now)
        if why is None or self.client.closed_error is not None or not await self.client.catch_up():
            return why
        return self.fault(self.client.clock())

    def advice(self) -> str:
        """What to do about the last :meth:`fault`."""
        return self.health.advice()

    async def close(self) -> None:
        """Stop pinging (the subscription ends with the connection)."""
        task, self._ping_task = self._ping_task, None
        if task is not None:
            task.cancel()
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await asyncio.wait({task}, timeout=0.5)
        with contextlib.suppress(ClientError):
            self.client.stop_request(self._status_name)


def _shows_motion(packet: Packet) -> bool:
    """The status packet shows a speed (one that does not decode shows nothing)."""
    try:
        value = packet.decode()
    except (ClientError, ProtocolError):
        return False
    numbers = value.numbers if isinstance(value, Update) else value
    return isinstance(numbers, UpdateNumbers) and (numbers.vel != 0 or numbers.rot_vel != 0)

"""A feed without a session: the one :class:`~rtmu.client.feed.FeedContext` for a bare client.

The command line (``rtmu ptz``), benchmarks and tests use one feed on its own over an
:class:`~rtmu.client.connection.AriaClient`: this context gives it what a session would — decoding,
tasks on the running loop, the robot's fields collected in :attr:`DetachedContext.robot` — and no
other feed.
"""

from __future__ import annotations

import asyncio
import time
from collections.abc import Callable, Coroutine
from dataclasses import replace
from typing import Any, TypeVar

from ..base.notices import Notice
from ..protocol.errors import ProtocolError
from ..protocol.payloads import Side, decode_payload
from ..values.state import MapModel, RobotState, StateChange
from ..values.target import Target
from .connection import AriaClient
from .feed import Feed
from .lease import DriveLease
from .session_config import SessionConfig
from .subscriptions import Handler

F = TypeVar("F", bound=Feed)


class DetachedContext:
    """Hands a lone feed what it needs; everything it publishes is kept (``changes``, ``notices``)."""

    def __init__(
        self,
        client: AriaClient | None = None,
        *,
        config: SessionConfig | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._client = client
        self.config = config or SessionConfig()
        self.clock = clock
        self.lease = DriveLease(clock=clock)
        self._robot = RobotState()
        self.changes: list[StateChange] = []
        self.notices: list[Notice] = []
        self.bad_payloads = 0
        self.tasks: set[asyncio.Task[Any]] = set()

    @property
    def client(self) -> AriaClient | None:
        return self._client

    @client.setter
    def client(self, client: AriaClient | None) -> None:
        self._client = client

    @property
    def target(self) -> Target | None:
        return None

    @property
    def robot(self) -> RobotState:
        return self._robot

    @property
    def map(self) -> MapModel:
        return MapModel()

    def publish(self, change: StateChange) -> None:
        self.changes.append(change)

    def robot_update(self, **changes: Any) -> None:
        self._robot = replace(self._robot, **changes)

    def notice(self, notice: Notice) -> None:
        self.notices.append(notice)

    def decode(self, name: str, payload: bytes) -> Any:
        try:
            return decode_payload(name, Side.REPLY, payload)
        except ProtocolError:
            self.bad_payloads += 1
            return None

    def spawn(self, coro: Coroutine[Any, Any, Any], name: str) -> None:
        """A task on the running loop; without one (a test feeding packets by hand) it is dropped."""
        try:
            task = asyncio.get_running_loop().create_task(coro, name=name)
        except RuntimeError:
            coro.close()
            return
        self.tasks.add(task)
        task.add_done_callback(self.tasks.discard)

    def kick(self) -> None:
        pass

    def sync_subscriptions(self) -> None:
        pass

    def handler_for(self, name: str) -> Handler | None:
        return None

    def feed(self, kind: type[F]) -> F:
        raise LookupError(f"a detached feed has no {kind.__name__} beside it")

"""What a data handler may use of the simulator and of the client it answers, as protocols.

The handlers (``handlers``, ``profiles``, ``ld_data``) are called by the server and
must not import it: these protocols name exactly what they reach for, so the
server imports the handlers and never the other way round.
"""

from __future__ import annotations

import asyncio
from collections import deque
from collections.abc import Callable
from typing import Protocol

from rtmu.protocol.datalist import DataList
from rtmu.protocol.payloads.config import ConfigRequest, SetConfig

from .catalogue import Row
from .config import SimConfig
from .geometry import Obstacles
from .mapserve import ServedMap
from .video import VideoFeed
from .world import World


class Meter(Protocol):
    percent: float
    """The process's CPU use over the last second."""


class ArConfigStore(Protocol):
    """The server's configuration (:class:`rtmu.sim.arconfig.SimArConfig`), as its handlers use it."""

    def packets(self, version: int, request: ConfigRequest) -> list[bytes]: ...

    def apply(self, request: SetConfig) -> tuple[str, bool]: ...

    def sections(self) -> list[str]: ...

    def values(self) -> list[tuple[str, str, str]]: ...

    defaults: list[tuple[str, str, str]]


class SimClient(Protocol):
    """One connected client, as a handler sees it."""

    ident: int
    self_identifier: str
    closed: bool
    writer: asyncio.StreamWriter
    """A handler that sends a long series (a file) awaits ``writer.drain()`` between packets."""

    def send(self, number: int, payload: bytes) -> None: ...

    def may_use(self, group: str) -> bool: ...


class SimHost(Protocol):
    """The simulator, as a handler sees it."""

    world: World
    map: ServedMap
    config: SimConfig
    datalist: DataList
    video: VideoFeed
    video_size: tuple[int, int]
    stop_log: deque[tuple[float, int, str]]

    @property
    def arconfig(self) -> ArConfigStore:
        """Read only, so the server's own store type fits."""
        ...

    @property
    def cpu(self) -> Meter:
        """Read only, so the server's own meter type (which also samples) fits."""
        ...

    def cycle_cached(self, key: str, make: Callable[[], bytes]) -> bytes: ...

    def broadcast(self, name: str, payload: bytes = b"", exclude: SimClient | None = None) -> int: ...

    def check_map(self) -> bool: ...

    def install_map(
        self, served: ServedMap, *, move_home: bool = False, obstacles: Obstacles | None = None
    ) -> None: ...

    file_md5: bytes

    def reset_pose(self) -> None: ...

    def custom_commands(self) -> tuple[Row, ...]: ...

    def video_trailer(self) -> bytes: ...

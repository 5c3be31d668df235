"""Where a fleet's robots come from: a fixed list of direct robots, or ARIA's central server.

The fleet (``rtmu.fleet.sessions``) does not care how it learns of a robot: a :class:`Roster`
tells it, through :class:`RosterEvent` values, that a robot became reachable at an
address (:class:`RobotAdded`), went away (:class:`RobotRemoved`), or that the whole
roster was lost (:class:`RosterLost`: the central server's connection ended, so every
robot reached through it is gone and every drive must stop) or is back
(:class:`RosterRestored`: its robots are announced again, as new robots). A direct profile is a
:class:`DirectRoster` (its robots are added at once and never leave); a central
server is watched by a roster that lives in ``client/central.py``.

Events are delivered through ``post`` (``GLib.idle_add`` in the window, a direct call
in tests), so a fleet always hears them on its own thread.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol


@dataclass(frozen=True, slots=True)
class RobotEndpoint:
    """One robot as a fleet reaches it."""

    name: str
    """The robot's name as the operator sees it; unique within one roster."""
    host: str
    port: int
    via: str = ""
    """Empty for a robot reached directly; ``"HOST:PORT"`` of the central server that forwards it."""


@dataclass(frozen=True, slots=True)
class RobotAdded:
    endpoint: RobotEndpoint


@dataclass(frozen=True, slots=True)
class RobotRemoved:
    name: str
    reason: str = ""


@dataclass(frozen=True, slots=True)
class RosterLost:
    """The source of the roster itself is gone (e.g. the central server): all its robots are gone."""

    reason: str
    retrying: bool = False
    """The roster keeps trying to reach its source; :class:`RosterRestored` says when it has."""


@dataclass(frozen=True, slots=True)
class RosterRestored:
    """The source is back after a :class:`RosterLost`; its robots follow as :class:`RobotAdded`."""


RosterEvent = RobotAdded | RobotRemoved | RosterLost | RosterRestored
Emit = Callable[[RosterEvent], None]


class Roster(Protocol):
    """A source of robots. ``start`` once; ``close`` ends it and emits nothing after."""

    def start(self, emit: Emit) -> None: ...

    def close(self) -> None: ...


class DirectRoster:
    """A fixed list of robots reached directly: all added at ``start``, none ever removed."""

    def __init__(self, endpoints: Sequence[RobotEndpoint]) -> None:
        names = [e.name for e in endpoints]
        if len(set(names)) != len(names):
            raise ValueError(f"robot names must be unique in a roster: {names}")
        self.endpoints = tuple(endpoints)
        self._closed = False

    def start(self, emit: Emit) -> None:
        for endpoint in self.endpoints:
            if self._closed:
                return
            emit(RobotAdded(endpoint))

    def close(self) -> None:
        self._closed = True

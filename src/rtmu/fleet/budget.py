"""How many robots a fleet window connects to at once, and which ones.

A central server may list hundreds or thousands of robots; a window that connected to each (its
network thread, its map, its 10 Hz status, its recording) stopped answering keys. So a fleet
connects to at most ``connect_at_most`` robots (the profile's ``connect_at_most``, 20 by default):
the first ones the roster names. The others are listed as "not connected"; selecting one connects
it on demand, and then the connected robot used least recently — never the selected one, never
one the server is navigating or one that is being driven — is let go again (disconnected
quietly: it was idle, so no stop is sent to it). Pure rules, GTK-free and network-free.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from typing import TypeVar

from ..settings.store import CONNECT_AT_MOST, MAX_CONNECT_AT_MOST

__all__ = ["CONNECT_AT_MOST", "MAX_CONNECT_AT_MOST", "to_connect", "to_let_go"]

S = TypeVar("S")


def to_connect(listed: Sequence[str], connected: Iterable[str], budget: int) -> list[str]:
    """The listed robots (by name, in list order) to connect now so that ``budget`` are connected."""
    have = set(connected)
    room = budget - len(have)
    if room <= 0:
        return []
    return [name for name in listed if name not in have][:room]


def to_let_go(
    sessions: Sequence[S],
    budget: int,
    *,
    keep: Callable[[S], bool],
    last_used: Callable[[S], float],
) -> list[S]:
    """The sessions to disconnect so that at most ``budget`` stay connected: least recently used first,
    never one that ``keep`` (selected, navigating, driving). Fewer when too many must be kept."""
    excess = len(sessions) - budget
    if excess <= 0:
        return []
    order = {id(s): i for i, s in enumerate(sessions)}
    candidates = sorted((s for s in sessions if not keep(s)), key=lambda s: (last_used(s), order[id(s)]))
    return candidates[:excess]

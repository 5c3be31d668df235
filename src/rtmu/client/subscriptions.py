"""A session's subscriptions as data: which data, how often, who handles it, and when it applies.

The session declares a tuple of :class:`Subscription` records instead of a
chain of ``if client.supports(...)`` calls, so the set can be read, tested and
replaced (a replay, a tool that wants less) without touching the session. A
record may also say *when* it is wanted (``only_while``): the data is then asked
for only while that holds, not for the whole connection.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Generic, TypeVar

from .connection import Packet

S = TypeVar("S")
"""The session type the handlers belong to."""
C = TypeVar("C")
"""The config type the intervals are read from."""


@dataclass(frozen=True, slots=True)
class Subscription(Generic[S, C]):
    """Subscribe to ``name`` every ``interval_ms`` (−1: broadcasts only) while the server offers it."""

    name: str
    interval_ms: int | Callable[[C], int]
    """A period in ms, or how to read it from the session's config."""
    handler: Callable[[S, Packet], None]
    """Called as ``handler(session, packet)`` (an unbound method of the session)."""
    needs: str | None = None
    """Only when the server offers this data too (``updateStrings`` goes with ``updateNumbers``)."""
    unless: str | None = None
    """Not when the server offers this data (the old ``update`` gives way to ``updateNumbers``)."""
    only_while: Callable[[S], bool] | None = None
    """Held only while this holds for the session (``getPath`` while navigating): the session asks
    again whenever the answer may have changed, and ends the subscription when it turns false."""

    def applies(self, offered: Callable[[str], bool]) -> bool:
        if not offered(self.name):
            return False
        if self.needs is not None and not offered(self.needs):
            return False
        return self.unless is None or not offered(self.unless)

    def interval(self, config: C) -> int:
        return self.interval_ms if isinstance(self.interval_ms, int) else self.interval_ms(config)


def applicable(
    subs: Iterable[Subscription[S, C]], offered: Callable[[str], bool]
) -> list[Subscription[S, C]]:
    """The subscriptions to make on a server that offers what ``offered(name)`` says, in order."""
    return [sub for sub in subs if sub.applies(offered)]

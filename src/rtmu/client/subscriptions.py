"""A feed's subscriptions as data: which data, how often, who handles it, and when it applies.

Each feed declares :class:`Subscription` records instead of a chain of ``if client.supports(...)``
calls, so the set can be read and tested without a server. A record may also say *when* it is
wanted (``only_while``): the data is then asked for only while that holds, not for the whole
connection. Two feeds may want the same data (``goalsUpdated``): the session then asks once, at the
shorter period, and hands each packet to both (:func:`merged`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

from .call_values import Packet

Handler = Callable[[Packet], None]


@dataclass(frozen=True, slots=True)
class Subscription:
    """Subscribe to ``name`` every ``interval_ms`` (−1: broadcasts only) while the server offers it."""

    name: str
    interval_ms: int
    handler: Handler
    needs: str | None = None
    """Only when the server offers this data too (``updateStrings`` goes with ``updateNumbers``)."""
    unless: str | None = None
    """Not when the server offers this data (the old ``update`` gives way to ``updateNumbers``)."""
    only_while: Callable[[], bool] | None = None
    """Held only while this holds (``getPath`` while navigating): the session asks again whenever the
    answer may have changed, and ends the subscription when it turns false."""

    def applies(self, offered: Callable[[str], bool]) -> bool:
        if not offered(self.name):
            return False
        if self.needs is not None and not offered(self.needs):
            return False
        return self.unless is None or not offered(self.unless)


def applicable(subs: Iterable[Subscription], offered: Callable[[str], bool]) -> list[Subscription]:
    """The subscriptions to make on a server that offers what ``offered(name)`` says, in order."""
    return [sub for sub in subs if sub.applies(offered)]


def merged(subs: Iterable[Subscription]) -> list[Subscription]:
    """One record per data name, in first-seen order: the shortest period, every handler called.

    Broadcasts (−1) give way to any period; ``only_while`` conditions combine with "or", and a record
    without one makes the merged record unconditional."""
    by_name: dict[str, list[Subscription]] = {}
    for sub in subs:
        by_name.setdefault(sub.name, []).append(sub)
    out = []
    for name, group in by_name.items():
        if len(group) == 1:
            out.append(group[0])
            continue
        periods = [s.interval_ms for s in group if s.interval_ms >= 0]
        handlers = tuple(s.handler for s in group)
        conditions = [s.only_while for s in group]
        when: Callable[[], bool] | None = None
        if all(c is not None for c in conditions):
            when = _any_of(tuple(c for c in conditions if c is not None))
        out.append(
            Subscription(
                name,
                min(periods) if periods else -1,
                _all_of(handlers),
                needs=group[0].needs,
                unless=group[0].unless,
                only_while=when,
            )
        )
    return out


def _any_of(conditions: tuple[Callable[[], bool], ...]) -> Callable[[], bool]:
    return lambda: any(c() for c in conditions)


def _all_of(handlers: tuple[Handler, ...]) -> Handler:
    def each(packet: Packet) -> None:
        for handler in handlers:
            handler(packet)

    return each

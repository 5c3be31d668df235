"""What the simulator heard from each connection: every request by name, in order, bounded.

Tests ask it who sent what — above all, that an observer (a recorder, ``rtmu watch``…) never
sent a motion request while someone else's navigation ran — without a mock in the way: the
log is filled where the server decodes each request.
"""

from __future__ import annotations

from collections import deque
from typing import NamedTuple

MAX_HEARD = 50_000
"""Requests kept (the oldest go first): minutes of a busy client's subscriptions and pings."""


class Heard(NamedTuple):
    at: float
    """World time (s) when it arrived."""
    session: int
    """The connection's number (1, 2, … in accept order; a switched socket counts too)."""
    peer: str
    """The client's address as ``host:port``."""
    name: str
    """ARIA's data name."""
    once: bool
    """A request-once (a command) rather than a subscription."""


class RequestLog:
    """Every request of every connection since the server started (up to :data:`MAX_HEARD`)."""

    def __init__(self, limit: int = MAX_HEARD) -> None:
        self._heard: deque[Heard] = deque(maxlen=limit)

    def note(self, at: float, session: int, peer: str, name: str, *, once: bool) -> None:
        self._heard.append(Heard(at, session, peer, name, once))

    def all(self) -> list[Heard]:
        return list(self._heard)

    def sessions_that_sent(self, names: frozenset[str]) -> set[int]:
        """The connections that sent any of ``names``."""
        return {h.session for h in self._heard if h.name in names}

    def of(self, session: int) -> list[Heard]:
        return [h for h in self._heard if h.session == session]

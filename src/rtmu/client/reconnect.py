"""When to try again after a lost connection: exponential backoff with jitter, pure and testable.

Reconnecting restores subscriptions and the map (the session's job) but never
motion: the drive lease ended with the connection, and only a fresh key press
grants a new one.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field

from .errors import ClientError, LoginRejected, NotSupported, ProtocolFault


@dataclass
class Backoff:
    """Delays ``initial·factor^n`` capped at ``maximum``, each spread by ±``jitter`` (a fraction)."""

    initial: float = 0.5
    factor: float = 2.0
    maximum: float = 10.0
    jitter: float = 0.2
    rng: random.Random = field(default_factory=random.Random)
    attempt: int = 0

    def next_delay(self) -> float:
        base = min(self.maximum, self.initial * self.factor**self.attempt)
        self.attempt += 1
        spread = base * self.jitter
        return max(0.0, base + self.rng.uniform(-spread, spread))

    def reset(self) -> None:
        self.attempt = 0


def worth_retrying(error: ClientError) -> bool:
    """Refused logins and servers that do not speak the protocol will not heal by themselves."""
    return not isinstance(error, (LoginRejected, ProtocolFault, NotSupported))

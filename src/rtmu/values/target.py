"""Where a robot session connects, and how: one frozen value from the profile to the wire.

The window's controller, the runner, the session (and its reconnects and the guardian's own login)
and every script pass this one value along instead of repeating ``host, port, user, password,
profile, auto_reconnect, protocol`` at each layer — a new connection option is added here once.
"""

from __future__ import annotations

from dataclasses import KW_ONLY, dataclass, field


@dataclass(frozen=True, slots=True)
class Target:
    """One robot server and the login to it (the password is never shown in a ``repr``)."""

    host: str
    port: int
    user: str = ""
    password: str = field(default="", repr=False)
    _: KW_ONLY
    profile: str = ""
    """The operator's profile the connection belongs to (shown with the connection; "" for scripts)."""
    auto_reconnect: bool = True
    """Connect again, backing off, when the link is lost (a replay or a one-shot script: False)."""
    protocol: str | None = None
    """The protocol string to log in with; None: answer with the one the server advertises."""
    server_key: str = field(default="", repr=False)
    """ARIA's optional server key, mixed into the password's digest (a server started with one)."""

"""Who may open the bridge's WebSocket: the handshake's checks, before anything is served.

The bridge streams the robot and, with ``--allow-drive``, lets a client drive it, so its port is
guarded against what a browser or a network can do on the operator's behalf:

* **Origin.** A browser names the page that opens a WebSocket, and a page cannot lie about it.
  Only Foxglove's own app origins (:data:`FOXGLOVE_ORIGINS`) and those the operator allows
  (``--allow-origin``) pass; any other web page the operator happens to visit is refused. A
  client that is no browser sends no Origin and passes (it could not be stopped by one anyway).
* **Host.** DNS rebinding points a hostile name at 127.0.0.1; the request then still names that
  host. Only IP addresses, ``localhost``, this machine's own names and ``--allow-host`` names pass.
* **Token.** Where clients may drive, the URL must carry the bridge's token (``?token=…``), made
  fresh at each start and printed once in the URL the operator opens. A host on the network that
  reaches the port does not know it.
* **Subprotocol.** The client must speak ``foxglove.sdk.v1`` or ``foxglove.websocket.v1`` (the
  same messages under two names); anything else is told so, not left guessing at a bare 400.

Pure: :meth:`Gate.check` reads the request's headers and path and answers a :class:`Refusal` or
None. :mod:`.foxglove_server` applies it to every handshake.
"""

from __future__ import annotations

import hmac
import ipaddress
import secrets
import socket
from collections.abc import Iterable
from dataclasses import dataclass, field
from functools import cache
from urllib.parse import parse_qs, urlsplit

SUBPROTOCOLS = ("foxglove.sdk.v1", "foxglove.websocket.v1")
"""Both names of the Foxglove WebSocket protocol, newest first (foxglove-sdk ≥ 0.9 / Foxglove 2+ offer
the first, older Foxglove, Lichtblick, PlotJuggler and ws-protocol clients the second)."""
FOXGLOVE_ORIGINS = frozenset({"https://app.foxglove.dev", "https://studio.foxglove.dev", "file://"})
"""Foxglove's web app (and its old address) and the desktop app, whose pages are local files."""
TOKEN_BYTES = 18
"""A token of 24 URL-safe characters: 144 random bits."""


@dataclass(frozen=True, slots=True)
class Refusal:
    status: int
    """The HTTP status the handshake is answered with."""
    reason: str
    """One sentence for the client (the response body) and the operator (``rtmu bridge`` prints it)."""


def new_token() -> str:
    return secrets.token_urlsafe(TOKEN_BYTES)


def normal_origin(origin: str) -> str:
    """``HTTPS://App.Foxglove.dev/`` → ``https://app.foxglove.dev`` (scheme and host compare without case)."""
    return origin.strip().rstrip("/").lower()


@cache
def local_names() -> frozenset[str]:
    """``localhost`` and the names of this machine (``host``, ``host.domain``, ``host.local``)."""
    names = {"localhost"}
    for name in (socket.gethostname(), socket.getfqdn()):
        name = name.lower().rstrip(".")
        if name:
            names.add(name)
            names.add(name.split(".", 1)[0] + ".local")
    return frozenset(names)


def _host_name(host: str) -> str:
    """The name or address of a ``Host`` header without its port or brackets, lower case."""
    host = host.strip().lower()
    if host.startswith("["):  # [::1]:8765
        return host[1 : host.find("]")] if "]" in host else host[1:]
    if host.count(":") == 1:
        host = host.split(":", 1)[0]
    return host.rstrip(".")


def _is_address(name: str) -> bool:
    try:
        ipaddress.ip_address(name)
    except ValueError:
        return False
    return True


@dataclass(frozen=True, slots=True)
class Gate:
    """The bridge's handshake policy. ``token`` None: no token asked (a bridge that never drives)."""

    origins: frozenset[str] = FOXGLOVE_ORIGINS
    hosts: frozenset[str] = field(default_factory=frozenset)
    """Host names allowed besides addresses, ``localhost`` and this machine's names."""
    token: str | None = None

    @classmethod
    def make(
        cls, *, allow_origins: Iterable[str] = (), allow_hosts: Iterable[str] = (), token: str | None = None
    ) -> Gate:
        origins = FOXGLOVE_ORIGINS | {normal_origin(o) for o in allow_origins if o.strip()}
        hosts = frozenset(_host_name(h) for h in allow_hosts if h.strip())
        return cls(origins=frozenset(origins), hosts=hosts, token=token)

    def host_allowed(self, name: str) -> bool:
        return (
            _is_address(name)
            or name == "localhost"
            or name.endswith(".localhost")
            or name in local_names()
            or name in self.hosts
        )

    def check(self, headers: Iterable[tuple[str, str]], path: str) -> Refusal | None:
        """None when the handshake may go on; else why not. ``headers``: (name, value) pairs as sent."""
        values: dict[str, list[str]] = {}
        for name, value in headers:
            values.setdefault(name.lower(), []).append(value)
        hosts = values.get("host", [])
        if len(hosts) != 1:
            return Refusal(400, "the request must name exactly one Host")
        host = _host_name(hosts[0])
        if not self.host_allowed(host):
            return Refusal(
                403,
                f"refused a request for host {host!r} (DNS rebinding?): connect by IP address, localhost "
                "or this machine's name, or start rtmu bridge with --allow-host NAME",
            )
        origins = values.get("origin", [])
        if len(origins) > 1:
            return Refusal(403, "the request names more than one Origin")
        if origins and normal_origin(origins[0]) not in self.origins:
            return Refusal(
                403,
                f"refused a browser page from Origin {origins[0].strip()!r}: only Foxglove's own app may "
                "connect; if that page is yours, start rtmu bridge with --allow-origin ORIGIN",
            )
        if self.token is not None:
            given = parse_qs(urlsplit(path).query).get("token", [])
            if not given:
                return Refusal(
                    401,
                    "this bridge lets clients drive the robot: open the URL rtmu bridge printed, it carries "
                    "the token (?token=…)",
                )
            if not any(hmac.compare_digest(t.encode(), self.token.encode()) for t in given[:1]):
                return Refusal(401, "the URL's token is not this bridge's: open the URL rtmu bridge printed")
        offered = {p.strip() for v in values.get("sec-websocket-protocol", []) for p in v.split(",")}
        if not offered & set(SUBPROTOCOLS):
            return Refusal(
                400,
                "this is a Foxglove WebSocket server: the client must offer the subprotocol "
                f"{SUBPROTOCOLS[0]} or {SUBPROTOCOLS[1]}",
            )
        return None


def loopback_only(bind: str) -> bool:
    """Whether a server bound to ``bind`` can be reached from this machine only (0.0.0.0, ::, a
    LAN address or a host name other than ``localhost`` can be reached from the network)."""
    name = bind.strip().strip("[]").lower()
    if name == "localhost":
        return True
    try:
        return ipaddress.ip_address(name).is_loopback
    except ValueError:
        return False

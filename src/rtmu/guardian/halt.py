"""The only thing a guardian can send: zero ``ratioDrive`` and ``stop``.

:class:`Halter` keeps the connection private and has one method; the payloads
are constants built here, so no code path in the guardian can carry nonzero
ratios (``tests/client/test_guardian.py`` checks this module's sends by AST).
"""

from __future__ import annotations

import contextlib

from ..client.connection import AriaClient
from ..client.errors import ClientError
from ..protocol.payloads.drive import RatioDrive

ZERO_RATIO_DRIVE: bytes = RatioDrive(0.0, 0.0, 0.0).encode()
IDENTIFIER = "rtmu-guardian"


class Halter:
    """Wraps a logged-in connection; :meth:`halt` is all it offers."""

    __slots__ = ("_client",)

    def __init__(self, client: AriaClient) -> None:
        self._client = client
        if client.supports("identSetSelfIdentifier"):  # so a server's log can tell who stopped it
            with contextlib.suppress(ClientError):
                client.send("identSetSelfIdentifier", IDENTIFIER)

    def halt(self) -> bool:
        """Zero ratios, then ``stop``; True if both were handed to the socket."""
        sent = 0
        if self._client.supports("ratioDrive"):
            with contextlib.suppress(ClientError):
                self._client.send("ratioDrive", ZERO_RATIO_DRIVE)
                sent += 1
        with contextlib.suppress(ClientError):
            self._client.send("stop")
            sent += 1
        return sent == 2 or (sent == 1 and not self._client.supports("ratioDrive"))

    async def flush(self) -> None:
        await self._client.flush()

    @property
    def connected(self) -> bool:
        return self._client.connected

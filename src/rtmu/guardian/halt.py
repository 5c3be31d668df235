"""The only things a guardian can send: zero ``ratioDrive`` and ``stop`` (and who it is).

:class:`Halter` keeps the connection private and has one method; the payloads are constants
built here, so no code path in the guardian can carry nonzero ratios
(``tests/client/test_guardian.py`` checks every request in the package by AST: they are all here).
"""

from __future__ import annotations

from ..protocol.errors import ProtocolError
from ..protocol.payloads.drive import RatioDrive
from ..protocol.payloads.server import SelfIdentifier
from .login import RobotLogin

ZERO_RATIO_DRIVE: bytes = RatioDrive(0.0, 0.0, 0.0).encode()
IDENTIFIER = "rtmu-guardian"
IDENTIFIER_ARGS: bytes = SelfIdentifier(IDENTIFIER).encode()


class Halter:
    """Wraps a logged-in connection; :meth:`halt` is all it offers."""

    __slots__ = ("_login",)

    def __init__(self, login: RobotLogin) -> None:
        self._login = login
        if login.supports("identSetSelfIdentifier"):  # so a server's log can tell who stopped it
            login.conn.request_once("identSetSelfIdentifier", IDENTIFIER_ARGS)
            login.flush()

    def halt(self) -> bool:
        """Zero ratios, then ``stop``, queued on the connection (then :meth:`flush`); True if both were."""
        conn = self._login.conn
        sent = 0
        if self._login.supports("ratioDrive"):
            try:
                conn.request_once("ratioDrive", ZERO_RATIO_DRIVE)
                sent += 1
            except ProtocolError:
                pass
        if self._login.supports("stop"):
            try:
                conn.request_once("stop")
                sent += 1
            except ProtocolError:
                pass
        return sent == 2 or (sent == 1 and not self._login.supports("ratioDrive"))

    def flush(self, timeout: float = 0.5) -> bool:
        return self._login.flush(timeout)

    @property
    def connected(self) -> bool:
        return self._login.active

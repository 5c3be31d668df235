"""Errors an operator (or a script) can act on, each with the exit code ``rtmu`` uses for it.

Every failure of the client surfaces as one of these, never as a bare
``OSError`` or ``asyncio.TimeoutError``: the window shows ``str(error)`` as is,
and the command line prints it on one line and exits with ``error.exit_code``.
"""

from __future__ import annotations

from ..base.exit_codes import EXIT_CONNECTION, EXIT_INTERNAL, EXIT_TIMEOUT, EXIT_UNSUPPORTED
from ..base.i18n import N_, Said, as_said
from ..base.refusals import refusal
from ..protocol.commands import RejectReason
from ..protocol.errors import ProtocolError


class ClientError(Exception):
    """Base of every client failure."""

    exit_code = EXIT_CONNECTION
    kind = "error"
    """Short machine-readable class (``ConnectionState.error_kind``)."""


class ConnectionRefused(ClientError):
    """Nothing listens on that host and port (the server is not running, or a wrong port)."""

    kind = "refused"


class ConnectionFailed(ClientError):
    """The TCP connection could not be made for another reason (unknown host, no route…)."""

    kind = "unreachable"


class HostNotFound(ConnectionFailed):
    """The host name does not resolve (a typo, or no DNS for it on this network)."""


class ClientTimeout(ClientError, TimeoutError):
    """The server did not answer in time (connect, login, or a request)."""

    exit_code = EXIT_TIMEOUT
    kind = "timeout"


class LoginRejected(ClientError):
    """The server refused the login; ``reason`` is ARIA's REJECTED code, ``text`` its own words."""

    kind = "login"

    def __init__(
        self, reason: int, text: str = "", advice: str = "", wanted_protocol: str | None = None
    ) -> None:
        self.reason = reason
        self.text = text
        self.wanted_protocol = wanted_protocol
        """Reason 4: the protocol string the server advertised (None: not known)."""
        why = as_said(advice) if advice else refusal(reason, text)
        super().__init__(Said(N_("login refused: {reason}"), reason=why))

    @property
    def bad_credentials(self) -> bool:
        return self.reason == RejectReason.BAD_USER_OR_PASSWORD


class ServerClosed(ClientError):
    """The connection ended: the server said goodbye, died, or we disconnected."""

    kind = "closed"


class ProtocolFault(ClientError):
    """The server sent something that is not ArNetworking (or not in the state we were in)."""

    kind = "protocol"


class MalformedReply(ProtocolFault, ProtocolError):
    """A reply arrived intact (checksum good) but its payload does not decode as that data's type.

    Also a :class:`~rtmu.protocol.errors.ProtocolError`, so code that already catches the
    protocol layer's errors keeps working; as a :class:`ClientError` it reaches the operator
    as one line (exit 3) instead of a traceback.
    """


class ReplyTooLarge(ProtocolFault):
    """A reply went past the bound its caller set (packets or bytes); the rest of it was dropped."""


class NotSupported(ClientError):
    """This server (or this user's permissions) does not offer the data a command needs."""

    exit_code = EXIT_UNSUPPORTED
    kind = "unsupported"

    def __init__(self, name: str, detail: str = "") -> None:
        self.name = name
        super().__init__(
            detail
            or Said(N_("this server does not offer {name} (or this user may not use it)"), name=repr(name))
        )


class MotionRefused(ClientError):
    """An observer's client was asked to send a motion request; nothing was put on the wire.

    Reaching this is a bug in the command that asked (an observer never commands motion).
    """

    exit_code = EXIT_INTERNAL
    kind = "observer"

    def __init__(self, name: str) -> None:
        self.name = name
        super().__init__(
            Said(
                N_("an observer never sends {name} (it changes how the robot moves); nothing was sent"),
                name=repr(name),
            )
        )

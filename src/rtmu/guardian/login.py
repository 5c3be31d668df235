"""The guardian's own connection to a robot: a plain non-blocking socket and the sans-I/O codec.

:class:`RobotLogin` connects, answers the server's introduction and waits for the data list —
driven by the guardian's one ``select`` loop (:mod:`.child`), so a newer login or the end of the
parent's pipe is heard while a slow server is still logging us in. Once logged in it only keeps
reading (a closed connection must be noticed) and lets :class:`~.halt.Halter` queue its two
requests. Nothing here imports asyncio or the client package: the guardian starts light, and its
stop cannot depend on the code it guards against.
"""

from __future__ import annotations

import contextlib
import errno
import os
import select
import socket
import time
from enum import Enum

from ..base.i18n import N_, Said
from ..base.refusals import refusal
from ..base.units import Quantity
from ..protocol.client_connection import ClientConnection
from ..protocol.errors import ProtocolError
from ..protocol.events import DataListReady, PeerShutdown, Rejected
from .messages import Hello

READ_CHUNK = 65536
NOT_ARIA_AFTER = 4096
"""Bytes received without one valid packet after which the peer is no ArNetworking server."""


class LoginState(Enum):
    CONNECTING = "connecting"
    LOGGING_IN = "logging in"
    READY = "ready"
    FAILED = "failed"
    """The login did not succeed (``error`` says why)."""
    CLOSED = "closed"
    """The connection ended after the login (``error`` says how)."""


class RobotLogin:
    """One login to one robot server, and then its connection. Single-threaded; never blocks
    except in :meth:`flush`, which is bounded."""

    def __init__(self, hello: Hello, now: float | None = None) -> None:
        self.hello = hello
        self.where = f"{hello.target.host}:{hello.target.port}"
        self.deadline = (time.monotonic() if now is None else now) + hello.timeout
        target = hello.target
        self.conn = ClientConnection(
            target.user, target.password, server_key=target.server_key, protocol_version=target.protocol
        )
        self.state = LoginState.CONNECTING
        self.error: Said | str = ""
        """Why the login failed or its connection ended: a :class:`Said` (English as a str, the
        operator's language through ``words()``)."""
        self._received = 0
        self._out = bytearray()
        self.sock: socket.socket | None = None
        try:
            family, kind, proto, _name, address = socket.getaddrinfo(
                hello.target.host, hello.target.port, type=socket.SOCK_STREAM
            )[0]
            self.sock = socket.socket(family, kind, proto)
            self.sock.setblocking(False)
            code = self.sock.connect_ex(address)
        except OSError as exc:
            self._fail(
                Said(N_("cannot connect to {where}: {error}"), where=self.where, error=exc.strerror or exc)
            )
            return
        if code not in (0, errno.EINPROGRESS, errno.EWOULDBLOCK):
            self._fail(
                Said(N_("cannot connect to {where}: {error}"), where=self.where, error=_describe(code))
            )

    # -- what the select loop asks -------------------------------------------------------------
    @property
    def active(self) -> bool:
        return self.state in (LoginState.CONNECTING, LoginState.LOGGING_IN, LoginState.READY)

    def wants_write(self) -> bool:
        return self.active and (self.state is LoginState.CONNECTING or bool(self._out))

    def fileno(self) -> int:
        return self.sock.fileno() if self.sock is not None else -1

    def on_writable(self) -> None:
        if self.state is LoginState.CONNECTING and self.sock is not None:
            code = self.sock.getsockopt(socket.SOL_SOCKET, socket.SO_ERROR)
            if code:
                self._fail(
                    Said(N_("cannot connect to {where}: {error}"), where=self.where, error=_describe(code))
                )
                return
            self.state = LoginState.LOGGING_IN
        self._send_some()

    def on_readable(self, now: float) -> None:
        if self.sock is None or not self.active or self.state is LoginState.CONNECTING:
            return
        try:
            data = self.sock.recv(READ_CHUNK)
        except BlockingIOError:
            return
        except OSError as exc:
            self._end(
                Said(
                    N_("the connection to {where} broke: {error}"),
                    where=self.where,
                    error=exc.strerror or exc,
                )
            )
            return
        if not data:
            self._end(Said(N_("{where} closed the connection"), where=self.where))
            return
        self._received += len(data)
        try:
            events = self.conn.receive_data(data, now)
        except ProtocolError as exc:
            self._end(Said(N_("{peer} is not an ArNetworking server: {error}"), peer=self.where, error=exc))
            return
        if self._received >= NOT_ARIA_AFTER and self.conn.decoder.stats.packets == 0:
            self._end(Said(N_("{where} is not an ArNetworking server"), where=self.where))
            return
        for event in events:
            if isinstance(event, Rejected):
                self._fail(Said(N_("login refused: {reason}"), reason=refusal(event.reason, event.text)))
                return
            if isinstance(event, PeerShutdown):
                self._end(Said(N_("{where} shut the connection down"), where=self.where))
                return
            if isinstance(event, DataListReady) and self.state is LoginState.LOGGING_IN:
                self.state = LoginState.READY
        self._send_some()

    def check_deadline(self, now: float) -> None:
        if self.state in (LoginState.CONNECTING, LoginState.LOGGING_IN) and now > self.deadline:
            self._fail(
                Said(
                    N_("{where} did not complete the login within {timeout}"),
                    where=self.where,
                    timeout=Quantity(self.hello.timeout, "s", None),
                )
            )

    def supports(self, name: str) -> bool:
        return self.state is LoginState.READY and self.conn.datalist.number(name) is not None

    # -- output --------------------------------------------------------------------------------
    def _take_queued(self) -> None:
        self._out += self.conn.data_to_send()  # only what the codec queued: the login and halt.py's sends

    def _send_some(self) -> None:
        self._take_queued()
        if self.sock is None or not self._out or self.state is LoginState.CONNECTING:
            return
        try:
            sent = self.sock.send(self._out)
        except BlockingIOError:
            return
        except OSError as exc:
            self._end(
                Said(
                    N_("the connection to {where} broke: {error}"),
                    where=self.where,
                    error=exc.strerror or exc,
                )
            )
            return
        del self._out[:sent]

    def flush(self, timeout: float = 0.5) -> bool:
        """Hand everything queued to the kernel, waiting at most ``timeout`` s; True when it went."""
        end = time.monotonic() + timeout
        self._send_some()
        while self._out and self.sock is not None and self.state is LoginState.READY:
            left = end - time.monotonic()
            if left <= 0:
                return False
            with contextlib.suppress(OSError, ValueError):
                select.select([], [self.sock], [], left)
            self._send_some()
        return not self._out

    # -- ending --------------------------------------------------------------------------------
    def close(self) -> None:
        """Log out (SHUTDOWN, best effort) and close the socket."""
        if self.state is LoginState.READY:
            self.conn.shutdown()
            self._send_some()
        self._close_socket()
        if self.active:
            self.state = LoginState.CLOSED

    def _cannot_connect(self, error: object) -> None:
        self._fail(Said(N_("cannot connect to {where}: {error}"), where=self.where, error=error))

    def _broke(self, error: object) -> None:
        self._end(Said(N_("the connection to {where} broke: {error}"), where=self.where, error=error))

    def _fail(self, why: Said) -> None:
        self.state, self.error = LoginState.FAILED, why
        self._close_socket()

    def _end(self, why: Said) -> None:
        if self.state is LoginState.READY:
            self.state, self.error = LoginState.CLOSED, why
            self._close_socket()
        else:
            self._fail(why)

    def _close_socket(self) -> None:
        sock, self.sock = self.sock, None
        if sock is not None:
            with contextlib.suppress(OSError):
                sock.close()


def _describe(code: int) -> str | Said:
    if code == errno.ECONNREFUSED:
        return Said(N_("connection refused (is the robot server running on that port?)"))
    return os.strerror(code) if code else Said(N_("unknown error"))

"""One logged-in ArNetworking connection on asyncio streams: :class:`AriaClient`.

It wraps the sans-I/O ``ClientConnection`` (all wire knowledge lives there and
in the typed payloads) and adds what needs a clock and a socket:

* ``connect`` returns once the login is done and the data list is complete;
* ``request`` subscribes a handler; ``request_once`` awaits a reply, collecting
  multi-packet replies (maps) to their end marker; ``stream`` yields them one by
  one; ``send`` fires a command that has no reply;
* **every await has a timeout** — connect, login, each reply packet, the close —
  so nothing can hang on a server that accepts and never answers;
* every failure is a typed :mod:`~rtmu.client.errors` error.

Which reply answers which request, and where a multi-packet reply ends, is the
sans-I/O connection's business (:mod:`rtmu.protocol.replies`: matching in order,
abandoned requests, the grace, the bounds); this class only waits on the events
it reports. The bytes travel over a :class:`~rtmu.client.link.Link` — a TCP
socket by default, or a recorded stream, or a test's feed (``opener=``).

Everything here runs on one asyncio loop (the network thread's, see
``runner``); handlers are called on that loop and must be quick.
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import logging
import sys
import time
from collections.abc import AsyncIterator, Callable

from ..base.i18n import N_, Said
from ..base.units import Quantity
from ..protocol.client_connection import ClientConnection, ClientState
from ..protocol.datalist import DataList
from ..protocol.decoder import DropStats
from ..protocol.errors import ProtocolError
from ..protocol.payloads import Payload
from ..protocol.replies import (
    ABANDON_GRACE,
    MAX_PENDING_PER_DATA,
    MAX_REPLY_BYTES,
    MAX_REPLY_PACKETS,
    TooManyPending,
)
from ..values.target import Target
from .call_values import Arg, Handler, Reply, encode_args, request_parts
from .defaults import CONNECT_TIMEOUT
from .errors import (
    ClientError,
    ClientTimeout,
    NotSupported,
    ProtocolFault,
    ServerClosed,
)
from .goodbye import CLOSE_TIMEOUT, flushed, say_goodbye
from .inbox import Inbox
from .link import READ_CHUNK, Link, Opener, open_tcp
from .login import log_in, open_link
from .reply_waiter import ReplyWaiter
from .roles import MotionGate, Role

log = logging.getLogger(__name__)

REPLY_TIMEOUT = 5.0
"""Default wait for a reply, and for each further packet of a multi-packet reply."""
CATCH_UP_ROUNDS = 8
"""Loop rounds :meth:`AriaClient.catch_up` gives the read loop at most (a flood must not hold a verdict)."""
MAX_WRITE_BUFFER = 1 << 20
"""A server that stops reading is dropped once this much output is queued (it would grow forever)."""


class AriaClient:
    """One connection. Create, ``await connect(...)``, use, ``await disconnect()``.

    ``on_close(error)`` is called once when the connection ends for any reason
    other than :meth:`disconnect` (``error`` says why, e.g. :class:`ServerClosed`).
    ``opener(host, port)`` makes the :class:`~rtmu.client.link.Link` (default: TCP).
    """

    def __init__(
        self,
        *,
        on_close: Callable[[ClientError], None] | None = None,
        clock: Callable[[], float] = time.monotonic,
        abandon_grace: float = ABANDON_GRACE,
        opener: Opener = open_tcp,
    ) -> None:
        self.on_close = on_close
        self.clock = clock
        self.opener = opener
        self._abandon_grace = abandon_grace
        self._max_pending = MAX_PENDING_PER_DATA
        self.host = ""
        self.port = 0
        self.user = ""
        self._conn: ClientConnection | None = None
        self._link: Link | None = None
        self._read_task: asyncio.Task[None] | None = None
        self._inbox = Inbox()
        """Subscriptions and waiting requests, where each incoming event goes (``inbox``)."""
        self._closed_error: ClientError | None = None
        self._closing = False
        self.handler_stats = self._inbox.stats
        """How the subscription handlers' calls went: errors, slow calls, the longest (``handler_stats``)."""
        self._gate = MotionGate(Role.OBSERVER)
        """Replaced at :meth:`connect` by the role asked for; never changed after."""

    # -- state -----------------------------------------------------------------------------
    @property
    def abandon_grace(self) -> float:
        """Seconds an abandoned request waits for a late reply (see :mod:`rtmu.protocol.replies`)."""
        return self._abandon_grace

    @abandon_grace.setter
    def abandon_grace(self, seconds: float) -> None:
        self._abandon_grace = seconds
        if self._conn is not None:
            self._conn.replies.abandon_grace = seconds

    @property
    def max_pending(self) -> int:
        """Requests of one data number that may wait for replies at once."""
        return self._max_pending

    @max_pending.setter
    def max_pending(self, count: int) -> None:
        self._max_pending = count
        if self._conn is not None:
            self._conn.replies.max_pending = count

    @property
    def connected(self) -> bool:
        return (
            self._conn is not None
            and self._conn.state is ClientState.CONNECTED
            and not self._closing
            and self._closed_error is None
        )

    @property
    def datalist(self) -> DataList:
        return self._conn.datalist if self._conn is not None else DataList()

    @property
    def server_words(self) -> tuple[str, str, str]:
        """(the server's version tag, the protocol string it asked for, the one we answered): for support."""
        conn = self._conn
        intro = None if conn is None else conn.introduction
        if conn is None or intro is None:
            return "", "", ""
        return intro.version_tag, intro.protocol_version, conn.sent_protocol_version or ""

    @property
    def drops(self) -> DropStats:
        """What the decoder threw away on this connection (bad checksums, garbage bytes…)."""
        return self._conn.decoder.stats if self._conn is not None else DropStats()

    def undecided(self) -> bool:
        """True while the decoder holds a header whose body has not come but sees valid packets
        going on behind it: the stream is alive and will be delivered within a few packets."""
        return self._conn is not None and self._conn.decoder.undecided > 0

    @property
    def last_packet_at(self) -> float | None:
        """When the last packet came (None before the first): the link's health reads it."""
        return self._inbox.last_packet_at

    @property
    def packets_received(self) -> int:
        return self._inbox.packets_received

    @property
    def closed_error(self) -> ClientError | None:
        """Why the connection ended (None while open or after a plain ``disconnect``)."""
        return self._closed_error

    @property
    def role(self) -> Role:
        """OBSERVER (no motion request ever leaves) or OPERATOR, as given to :meth:`connect`."""
        return self._gate.role

    @property
    def drove(self) -> bool:
        """True once this connection sent a motion request that does more than stop: only then does
        it stop the robot when it ends (its own drive, never somebody else's navigation)."""
        return self._gate.drove

    def supports(self, name: str) -> bool:
        """True if the server offers ``name`` to this user (after ``connect``)."""
        return self._conn is not None and name in self._conn.datalist

    # -- connect ---------------------------------------------------------------------------
    async def connect(
        self, target: Target, *, timeout: float = CONNECT_TIMEOUT, role: Role = Role.OPERATOR
    ) -> DataList:
        """Open the link to ``target``, log in and wait for the complete data list, all within ``timeout`` s.

        ``role`` is fixed for the connection's life: an OBSERVER's motion requests are refused
        (:class:`~rtmu.client.errors.MotionRefused`) before anything is put on the wire.
        """
        if self._conn is not None:
            raise RuntimeError("AriaClient objects are single-use: make a new one to connect again")
        self._gate = MotionGate(role)
        host, port = target.host, target.port
        self.host, self.port, self.user = host, port, target.user
        self._conn = ClientConnection(
            target.user, target.password, server_key=target.server_key, protocol_version=target.protocol
        )
        self._conn.replies.abandon_grace = self._abandon_grace
        self._conn.replies.max_pending = self._max_pending
        deadline = asyncio.get_running_loop().time() + timeout
        self._link = await open_link(self.opener, host, port, deadline, timeout)
        try:
            async with asyncio.timeout_at(deadline):
                peer = f"{host}:{port}"
                await log_in(self._link, self._conn, peer, self.clock, self._flush, self._inbox.deliver)
        except TimeoutError:
            self._abort()
            raise ClientTimeout(
                Said(
                    N_("{where} accepted the connection but did not complete the login within {timeout}"),
                    where=f"{host}:{port}",
                    timeout=Quantity(timeout, "s", None),
                )
            ) from None
        except BaseException:
            self._abort()
            raise
        self._read_task = asyncio.get_running_loop().create_task(self._read_loop(), name="aria-read")
        return self._conn.datalist

    # -- requests --------------------------------------------------------------------------
    def _number(self, name: str) -> int:
        conn = self._require_open()
        number = conn.datalist.number(name)
        if number is None:
            raise NotSupported(name)
        return number

    def _require_open(self) -> ClientConnection:
        if self._closed_error is not None:
            raise self._closed_error
        if self._conn is None or not self.connected:
            raise ServerClosed("not connected")
        return self._conn

    def request(self, name: str, interval_ms: int, handler: Handler, *args: Arg) -> None:
        """Subscribe: ``handler(packet)`` now and every ``interval_ms`` (−1: broadcasts only).

        Requesting the same name again replaces the handler and interval (ARIA then sends no
        immediate reply).
        """
        number = self._number(name)
        payload = encode_args(args)
        self._gate.admit(name, payload)
        self._inbox.handlers[number] = handler
        self._conn.request(name, interval_ms, payload)  # type: ignore[union-attr]
        self._flush()

    def listen(self, name: str, handler: Handler | None) -> None:
        """Hear ``name``'s packets that no tracked request claims, sending nothing (ARIA's ``addHandler``).

        For data whose answers do not pair one-to-one with requests (``putFile``: errors only, then one
        result); ``None`` stops listening. NotSupported when the server does not list ``name``.
        """
        number = self._number(name)
        if handler is None:
            self._inbox.handlers.pop(number, None)
        else:
            self._inbox.handlers[number] = handler

    async def drain(self, timeout: float = REPLY_TIMEOUT) -> None:
        """Wait until our output is back under the link's high-water mark (a bulk sender's pacing).

        ClientTimeout when the server reads nothing for ``timeout`` s; the connection's own error
        once it has ended.
        """
        self._require_open()
        link = self._link
        assert link is not None
        try:
            async with asyncio.timeout(timeout):
                await link.drain()
        except TimeoutError:
            raise ClientTimeout(
                f"{self.host}:{self.port} read nothing of what we sent for {timeout:g} s"
            ) from None
        except OSError as exc:
            reason = exc.strerror or exc
            self._fail(ServerClosed(f"the connection to {self.host}:{self.port} broke: {reason}"))
        self._require_open()

    def subscribed(self, name: str) -> bool:
        """True while a handler holds a subscription to ``name`` (another ``request`` would replace it)."""
        number = self._conn.datalist.number(name) if self._conn is not None else None
        return number is not None and number in self._inbox.handlers

    def stop_request(self, name: str) -> None:
        """End a subscription (no reply). Unknown or unsubscribed names are ignored."""
        number = self._conn.datalist.number(name) if self._conn is not None else None
        if number is None or not self.connected:
            return
        self._inbox.handlers.pop(number, None)
        self._conn.request_stop(name)  # type: ignore[union-attr]
        self._flush()

    def send(self, what: str | Payload, *args: Arg) -> None:
        """Run a command once without waiting for anything.

        ``send(RatioDrive(…))``: the typed payload names its data; ``send("stop")``,
        ``send("turnByAngle", 90)``: a name and arguments (see :func:`encode_args`).
        """
        name, payload = request_parts(what, args)
        self._number(name)
        self._gate.admit(name, payload)
        self._conn.request_once(name, payload)  # type: ignore[union-attr]
        self._flush()

    async def request_once(
        self,
        what: str | Payload,
        *args: Arg,
        timeout: float = REPLY_TIMEOUT,
        expect: int | None = None,
        until: Callable[[bytes], bool] | None = None,
        max_packets: int = MAX_REPLY_PACKETS,
        max_bytes: int = MAX_REPLY_BYTES,
        read_arrived: bool = False,
    ) -> Reply:
        """Run ``what`` (a data name, or a typed payload naming its data) once and await its reply.

        Multi-packet replies (``getMap``, ``getMapBinary``, RETURN_UNTIL_EMPTY data) are
        collected to their end marker; ``timeout`` bounds the wait for *each* packet, so a big
        map may take longer overall but a stalled one fails. ``expect=n`` waits for exactly n
        packets (``getSensorCurrent`` with n names); ``until(payload) -> bool`` lets the caller
        decide where the reply ends (e.g. a map assembler's ``feed``; a ``ProtocolError`` it
        raises fails the request with :class:`ProtocolFault`). Data that has no reply
        (RETURN_NONE) is sent and an empty :class:`Reply` returned at once. A reply longer
        than ``max_packets`` packets or ``max_bytes`` payload bytes fails with
        :class:`ReplyTooLarge` (for big maps use ``rtmu.client.mapload`` or :meth:`stream`).
        ``read_arrived``: a timeout is final only once what has already arrived is read (see
        :meth:`ask_in_time`).
        """
        name, payload = request_parts(what, args)
        waiter = self._start(name, payload, expect, until, False, max_packets, max_bytes)
        if waiter is None:
            return Reply(name, (), self.clock())
        payloads = await waiter.collect(timeout, arrived=self._take_in_arrived if read_arrived else None)
        return Reply(name, payloads, self.clock())

    async def ask_in_time(self, name: str, deadline: float) -> Reply:
        """``request_once`` judged on what *arrived*: a ping's answer.

        A reply that came within ``deadline`` s counts even when this loop was run too late to read
        it in time: the timer and the answer wake the loop together, and the timer runs first. So
        when the deadline passes, what the kernel already holds is read (:meth:`catch_up`) before it
        is called missed. No answer then: :class:`ClientTimeout`. A ping answered in time takes
        ``request_once``'s path exactly.
        """
        return await self.request_once(name, timeout=deadline, read_arrived=True)

    async def _take_in_arrived(self) -> None:
        """:meth:`catch_up`, then the rounds a routed reply needs to wake its waiter."""
        await self.catch_up()
        for _ in range(2):
            await asyncio.sleep(0)

    async def stream(
        self,
        what: str | Payload,
        *args: Arg,
        timeout: float = REPLY_TIMEOUT,
        expect: int | None = None,
        until: Callable[[bytes], bool] | None = None,
        max_packets: int = MAX_REPLY_PACKETS,
        max_bytes: int = MAX_REPLY_BYTES,
    ) -> AsyncIterator[bytes]:
        """Like :meth:`request_once` but yields each payload as it arrives (progress for big maps).

        Nothing is kept after it is yielded; the bounds apply to packets received but not
        read yet (a reader that falls that far behind gets :class:`ReplyTooLarge`).
        """
        name, payload = request_parts(what, args)
        waiter = self._start(name, payload, expect, until, True, max_packets, max_bytes)
        if waiter is None:
            return
        conn = self._conn  # set by connect, never unset
        assert conn is not None
        taken = functools.partial(conn.reply_taken, waiter.reply)  # the bounds count unread packets only
        async with contextlib.aclosing(waiter.items(timeout, taken)) as items:
            async for item in items:
                yield item

    async def follow(
        self,
        what: str | Payload,
        *args: Arg,
        until: Callable[[bytes], bool],
        timeout: float = REPLY_TIMEOUT,
        progress: Callable[[int], None] | None = None,
    ) -> int:
        """A reply whose packets only ``until`` reads (a map assembler: it bounds and keeps what it
        needs): nothing is queued or kept for the caller, so a million-packet map costs no queue
        and no wake-up per packet. Returns the packet count; ``progress(count)`` after each burst;
        ``timeout`` bounds the wait for each packet."""
        name, payload = request_parts(what, args)
        waiter = self._start(name, payload, None, until, True, sys.maxsize, sys.maxsize, queued=False)
        if waiter is None:
            return 0
        return await waiter.follow(timeout, progress)

    def _start(
        self,
        name: str,
        payload: bytes,
        expect: int | None,
        until: Callable[[bytes], bool] | None,
        streaming: bool,
        max_packets: int = MAX_REPLY_PACKETS,
        max_bytes: int = MAX_REPLY_BYTES,
        *,
        queued: bool = True,
    ) -> ReplyWaiter | None:
        self._number(name)
        self._gate.admit(name, payload)
        conn = self._conn
        assert conn is not None
        try:
            reply = conn.request_reply(
                name, payload, now=self.clock(), expect=expect, until=until,
                streaming=streaming, max_packets=max_packets, max_bytes=max_bytes,
            )  # fmt: skip
        except TooManyPending as exc:
            raise ClientError(
                f"{exc.count} requests for {name!r} are already waiting for {self.host}:{self.port} "
                "to answer; not sending more"
            ) from None
        self._flush()
        if reply is None:
            return None
        waiter = self._inbox.waiters[reply] = ReplyWaiter(
            reply,
            streaming,
            abandon=self._abandon,
            drops=lambda: self.drops,
            peer=f"{self.host}:{self.port}",
            queued=queued,
        )
        return waiter

    def _abandon(self, waiter: ReplyWaiter) -> None:
        """A waiter gave up: its slot stays so late packets still line up, but nobody waits on it."""
        self._inbox.waiters.pop(waiter.reply, None)
        waiter.fail(ClientTimeout(f"{waiter.reply.name!r} abandoned"))
        if self._conn is not None:
            self._conn.abandon_reply(waiter.reply, self.clock())

    # -- I/O -------------------------------------------------------------------------------
    def _flush(self) -> None:
        if self._conn is None or self._link is None:
            return
        data = self._conn.data_to_send()
        if not data or self._link.is_closing():
            return
        self._link.write(data)
        if self._link.backlog() > MAX_WRITE_BUFFER:
            self._fail(ServerClosed(f"{self.host}:{self.port} stopped reading; the connection was dropped"))

    async def _read_loop(self) -> None:
        assert self._link is not None and self._conn is not None
        try:
            while True:
                data = await self._link.read(READ_CHUNK)
                if not data:
                    self._fail(ServerClosed(f"{self.host}:{self.port} closed the connection"))
                    return
                now = self.clock()
                if not self._inbox.route(self._conn.receive_data(data, now), now):
                    self._fail(ServerClosed(f"{self.host}:{self.port} shut down"))
                    return
                self._flush()
        except asyncio.CancelledError:
            raise
        except ProtocolError as exc:
            self._fail(ProtocolFault(f"{self.host}:{self.port} broke the protocol: {exc}"))
        except OSError as exc:
            reason = exc.strerror or exc
            self._fail(ServerClosed(f"the connection to {self.host}:{self.port} broke: {reason}"))

    def _fail(self, error: ClientError) -> None:
        """The connection is over (not by our choice): fail every waiter, tell ``on_close`` once."""
        if self._closed_error is not None or self._closing:
            return
        self._closed_error = error
        self._teardown(error)
        if self.on_close is not None:
            try:
                self.on_close(error)
            except Exception:
                log.exception("on_close callback failed")

    def _teardown(self, error: ClientError) -> None:
        self._inbox.fail_waiters(error)
        if self._conn is not None:
            self._conn.replies.clear()
        self._inbox.handlers.clear()
        self._abort()

    def _abort(self) -> None:
        if self._link is not None:
            self._link.abort()

    def unread(self) -> int:
        """Bytes that have arrived from the server but not yet been read (kernel and stream buffer)."""
        link = self._link
        return 0 if link is None or self._closed_error is not None else link.unread()

    async def catch_up(self) -> int:
        """Before a verdict of silence: let the read loop take in what has already arrived.

        A busy laptop may run this thread 150–300 ms late; a status that came meanwhile sits unread
        in the socket, and the link would be called stale on a status the kernel already holds.
        This yields to the loop (a few rounds at most, however much keeps coming) until nothing is
        left unread. Returns the bytes that were waiting — 0, at no cost, when the silence is real.
        """
        waiting = self.unread()
        for _ in range(CATCH_UP_ROUNDS if waiting else 0):
            await asyncio.sleep(0)  # the selector reports the socket, then the read task routes it
            if not self.unread():  # (the read task routes what it takes from the buffer at once)
                break
        return waiting

    async def flush(self, timeout: float = CLOSE_TIMEOUT) -> bool:
        """Wait, at most ``timeout`` s, until everything sent has been handed to the kernel.

        True when nothing is left in our buffer (``rtmu drive`` checks that its stop has left
        before the process is suspended). Never raises.
        """
        return self._link is not None and await flushed(self._link, timeout)

    async def disconnect(self) -> None:
        """Say goodbye and close within :data:`~rtmu.client.goodbye.CLOSE_TIMEOUT` s (``goodbye``).
        Safe to call twice, or unconnected."""
        if self._closing:
            return
        self._closing = True
        task = self._read_task
        if task is not None and task is not asyncio.current_task():
            task.cancel()
        if self._conn is not None and self._link is not None and self._closed_error is None:
            await say_goodbye(self._conn, self._link, task)
        self._teardown(ServerClosed("disconnected"))
        if task is not None and task is not asyncio.current_task() and not task.done():
            # Bounded: a reader that will not end must not keep the caller (a window closing) waiting.
            await asyncio.wait({task}, timeout=CLOSE_TIMEOUT)

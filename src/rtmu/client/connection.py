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
import logging
import socket
import sys
import time
from collections.abc import AsyncIterator, Callable, Iterable
from dataclasses import dataclass, field

from ..protocol.client_connection import ClientConnection, ClientState, named, protocol_advice
from ..protocol.commands import RejectReason
from ..protocol.datalist import DataList
from ..protocol.decoder import DropStats
from ..protocol.errors import ProtocolError
from ..protocol.events import (
    DataListReady,
    DataReceived,
    Event,
    PeerShutdown,
    Rejected,
    ReplyComplete,
    ReplyError,
    ReplyFailed,
    ReplyId,
    ReplyPacket,
)
from ..protocol.fields import FieldWriter
from ..protocol.packet import MAX_LENGTH
from ..protocol.payloads import Payload, Side, decode_payload
from ..protocol.replies import (
    ABANDON_GRACE,
    MAX_PENDING_PER_DATA,
    MAX_REPLY_BYTES,
    MAX_REPLY_PACKETS,
    TooManyPending,
)
from .defaults import CONNECT_TIMEOUT, DEFAULT_PORT
from .errors import (
    ClientError,
    ClientTimeout,
    ConnectionFailed,
    ConnectionRefused,
    HostNotFound,
    LoginRejected,
    MalformedReply,
    NotSupported,
    ProtocolFault,
    ReplyTooLarge,
    ServerClosed,
)
from .link import Link, Opener, open_tcp
from .roles import MotionGate, Role

log = logging.getLogger(__name__)

REPLY_TIMEOUT = 5.0
"""Default wait for a reply, and for each further packet of a multi-packet reply."""
CLOSE_TIMEOUT = 0.2
"""How long ``disconnect`` lets the goodbye flush before cutting the socket."""
LINGER_TIMEOUT = 0.5
"""How long ``disconnect`` reads on after its goodbye, waiting for the server to close first."""
MAX_WRITE_BUFFER = 1 << 20
"""A server that stops reading is dropped once this much output is queued (it would grow forever)."""
READ_CHUNK = 1 << 16
SLOW_HANDLER = 0.01
"""A subscription handler that runs longer than this on the loop is counted and logged (the soak's
promise: no handler over 10 ms on the loop that sends the stops)."""
NOT_ARIA_AFTER = 4096
"""Bytes received during login without one valid packet after which the peer is not ArNetworking
(a real server's introduction is one small packet, sent at once)."""
TEXT_BANNERS = (b"HTTP/", b"SSH-", b"RFB ", b"220 ", b"220-", b"+OK", b"* OK")
"""How other common servers open a connection: such a peer is reported at once, not after --timeout."""
Arg = Payload | bytes | bytearray | str | float | int | bool


def encode_args(args: tuple[Arg, ...]) -> bytes:
    """Request arguments → payload bytes.

    A typed :class:`Payload` encodes itself; ``bytes`` go as they are; ``str`` is an
    ARIA string; ``bool`` a ubyte 0/1; other numbers an ARIA double (as text).
    Integer fields of other sizes: pass bytes built with ``FieldWriter`` or a typed payload.
    """
    w = FieldWriter()
    for arg in args:
        if isinstance(arg, Payload):
            w.raw(arg.encode())
        elif isinstance(arg, (bytes, bytearray)):
            w.raw(arg)
        elif isinstance(arg, str):
            w.string(arg)
        elif isinstance(arg, bool):
            w.ubyte(1 if arg else 0)
        elif isinstance(arg, (int, float)):
            w.double(float(arg))
        else:
            raise TypeError(f"cannot encode request argument {arg!r}")
    return w.bytes()


@dataclass(frozen=True, slots=True)
class Reply:
    """The packet(s) answering one request: ``payloads`` in arrival order (one for most data)."""

    name: str
    payloads: tuple[bytes, ...]
    received_at: float = field(compare=False)

    @property
    def payload(self) -> bytes:
        """The first (usually only) payload; ``b""`` if there was none."""
        return self.payloads[0] if self.payloads else b""

    def decode(self) -> Payload:
        """The first payload as its typed reply class; :class:`MalformedReply` if it does not decode."""
        return _decode_typed(self.name, self.payload, "replies")


@dataclass(frozen=True, slots=True)
class Packet:
    """One reply or broadcast packet handed to a subscription handler."""

    name: str
    payload: bytes
    received_at: float

    def decode(self) -> Payload:
        return _decode_typed(self.name, self.payload, "packets")


def _decode_typed(name: str, payload: bytes, what: str) -> Payload:
    try:
        typed = decode_payload(name, Side.REPLY, payload)
    except ProtocolError as exc:
        raise MalformedReply(f"the server sent a malformed {name!r} packet: {exc}") from None
    if typed is None:
        raise NotSupported(name, f"RTMU has no decoder for {name!r} {what}")
    return typed


Handler = Callable[[Packet], None]


class _Waiter:
    """The asyncio side of one tracked request: what ``request_once`` or ``stream`` waits on."""

    __slots__ = ("count", "error", "finished", "payloads", "progress", "queue", "reply")

    def __init__(self, reply: ReplyId, streaming: bool, *, queued: bool = True) -> None:
        self.reply = reply
        self.queue: asyncio.Queue[bytes | None] | None = asyncio.Queue() if streaming and queued else None
        self.progress = asyncio.Event()
        self.payloads: tuple[bytes, ...] = ()
        self.count = 0
        self.finished = False
        self.error: ClientError | None = None

    def packet(self, payload: bytes) -> None:
        self.count += 1
        if self.queue is not None:
            self.queue.put_nowait(payload)
        self.progress.set()

    def complete(self, payloads: tuple[bytes, ...]) -> None:
        self.finished = True
        self.payloads = payloads
        if self.queue is not None:
            self.queue.put_nowait(None)
        self.progress.set()

    def fail(self, error: ClientError, *, drop_unread: bool = False) -> None:
        """The reply will not come; ``drop_unread``: a stream's reader gets the error before stale packets."""
        if self.finished:
            return
        self.finished = True
        self.error = error
        if self.queue is not None:
            while drop_unread and not self.queue.empty():
                self.queue.get_nowait()
            self.queue.put_nowait(None)
        self.progress.set()


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
        self._handlers: dict[int, Handler] = {}
        self._waiters: dict[ReplyId, _Waiter] = {}
        self._closed_error: ClientError | None = None
        self._closing = False
        self.handler_errors = 0
        """Exceptions raised by subscription handlers (logged, never fatal)."""
        self.slow_handlers = 0
        """Handler calls that took longer than :data:`SLOW_HANDLER` (logged: they delay every packet)."""
        self.max_handler_seconds = 0.0
        """The longest one handler call has held the loop (soak and health figures)."""
        self.max_handler_cpu_seconds = 0.0
        """The most CPU one handler call used: its own work, without time the thread was descheduled."""
        self.slow_handlers_cpu = 0
        """Handler calls whose own CPU time went over :data:`SLOW_HANDLER`."""
        self.last_packet_at: float | None = None
        self.packets_received = 0
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

    def _no_reply(self, message: str) -> ClientError:
        """A timeout, unless the server sent a packet over ARIA's limit: that is then why (dropped)."""
        size = self.drops.largest_over_limit
        if size:
            limit = f"{MAX_LENGTH:,}".replace(",", " ")
            return ProtocolFault(
                f"{message}: the server sent a packet of {size} bytes, over ArNetworking's "
                f"{limit}-byte limit, so it was dropped"
            )
        return ClientTimeout(message)

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
        self,
        host: str,
        port: int = DEFAULT_PORT,
        user: str | None = None,
        password: str | None = None,
        *,
        timeout: float = CONNECT_TIMEOUT,
        server_key: str = "",
        protocol: str | None = None,
        role: Role = Role.OPERATOR,
    ) -> DataList:
        """Open the link, log in and wait for the complete data list, all within ``timeout`` s.

        ``role`` is fixed for the connection's life: an OBSERVER's motion requests are refused
        (:class:`~rtmu.client.errors.MotionRefused`) before anything is put on the wire.
        """
        if self._conn is not None:
            raise RuntimeError("AriaClient objects are single-use: make a new one to connect again")
        self._gate = MotionGate(role)
        self.host, self.port, self.user = host, port, user or ""
        self._conn = ClientConnection(
            user or "", password or "", server_key=server_key, protocol_version=protocol
        )
        self._conn.replies.abandon_grace = self._abandon_grace
        self._conn.replies.max_pending = self._max_pending
        deadline = asyncio.get_running_loop().time() + timeout
        try:
            async with asyncio.timeout_at(deadline):
                self._link = await self.opener(host, port)
        except TimeoutError:
            raise ClientTimeout(f"connecting to {host}:{port} timed out after {timeout:g} s") from None
        except ConnectionRefusedError:
            raise ConnectionRefused(
                f"connection refused by {host}:{port} (is the robot server running on that port?)"
            ) from None
        except socket.gaierror as exc:
            raise HostNotFound(f"cannot find host {host!r}: {exc.strerror or exc}") from None
        except OSError as exc:
            raise ConnectionFailed(f"cannot connect to {host}:{port}: {exc.strerror or exc}") from None
        try:
            async with asyncio.timeout_at(deadline):
                await self._login()
        except TimeoutError:
            self._abort()
            raise ClientTimeout(
                f"{host}:{port} accepted the connection but did not complete the login within {timeout:g} s"
            ) from None
        except BaseException:
            self._abort()
            raise
        self._read_task = asyncio.get_running_loop().create_task(self._read_loop(), name="aria-read")
        return self._conn.datalist

    async def _login(self) -> None:
        assert self._link is not None and self._conn is not None
        received = 0
        while True:
            try:
                data = await self._link.read(READ_CHUNK)
            except OSError as exc:
                raise ServerClosed(f"the connection broke during login: {exc.strerror or exc}") from None
            if not data:
                raise ServerClosed(f"{self.host}:{self.port} closed the connection during login")
            if received == 0 and data.startswith(TEXT_BANNERS):
                banner = data[:40].split(b"\n")[0].decode("ascii", "replace").strip()
                raise ProtocolFault(
                    f"{self.host}:{self.port} is not an ArNetworking server (it said {banner!r})"
                )
            received += len(data)
            now = self.clock()
            try:
                events = self._conn.receive_data(data, now)
            except ProtocolError as exc:
                raise ProtocolFault(f"{self.host}:{self.port} is not an ArNetworking server: {exc}") from None
            if received >= NOT_ARIA_AFTER and self._conn.decoder.stats.packets == 0:
                raise ProtocolFault(
                    f"{self.host}:{self.port} is not an ArNetworking server "
                    f"({received} bytes without a single valid packet)"
                )
            self._flush()
            ready = False
            for event in events:
                if isinstance(event, Rejected):
                    raise login_rejected(self._conn, event)
                if isinstance(event, PeerShutdown):
                    raise ServerClosed(f"{self.host}:{self.port} shut the connection down during login")
                if isinstance(event, DataListReady):
                    ready = True
                elif isinstance(event, DataReceived):
                    self._deliver(event.command, event.name, event.payload, now)
            if ready:
                return

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
        self._handlers[number] = handler
        self._conn.request(name, interval_ms, payload)  # type: ignore[union-attr]
        self._flush()

    def listen(self, name: str, handler: Handler | None) -> None:
        """Hear ``name``'s packets that no tracked request claims, sending nothing (ARIA's ``addHandler``).

        For data whose answers do not pair one-to-one with requests (``putFile``: errors only, then one
        result); ``None`` stops listening. NotSupported when the server does not list ``name``.
        """
        number = self._number(name)
        if handler is None:
            self._handlers.pop(number, None)
        else:
            self._handlers[number] = handler

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
        return number is not None and number in self._handlers

    def stop_request(self, name: str) -> None:
        """End a subscription (no reply). Unknown or unsubscribed names are ignored."""
        number = self._conn.datalist.number(name) if self._conn is not None else None
        if number is None or not self.connected:
            return
        self._handlers.pop(number, None)
        self._conn.request_stop(name)  # type: ignore[union-attr]
        self._flush()

    def send(self, what: str | Payload, *args: Arg) -> None:
        """Run a command once without waiting for anything.

        ``send(RatioDrive(…))``: the typed payload names its data; ``send("stop")``,
        ``send("turnByAngle", 90)``: a name and arguments (see :func:`encode_args`).
        """
        name, payload = _request(what, args)
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
        """
        name, payload = _request(what, args)
        waiter = self._start(name, payload, expect, until, False, max_packets, max_bytes)
        if waiter is None:
            return Reply(name, (), self.clock())
        try:
            while not waiter.finished:
                waiter.progress.clear()
                try:
                    async with asyncio.timeout(timeout):
                        await waiter.progress.wait()
                except TimeoutError:
                    got = waiter.count
                    self._abandon(waiter)
                    raise self._no_reply(
                        f"no reply to {name!r} from {self.host}:{self.port} within {timeout:g} s"
                        + (f" (after {got} packets)" if got else "")
                    ) from None
        finally:
            if not waiter.finished:  # cancelled: the slot must not wait for ever either
                self._abandon(waiter)
        if waiter.error is not None:
            raise waiter.error
        return Reply(name, waiter.payloads, self.clock())

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
        name, payload = _request(what, args)
        waiter = self._start(name, payload, expect, until, True, max_packets, max_bytes)
        if waiter is None:
            return
        queue = waiter.queue
        assert queue is not None
        try:
            while True:
                try:
                    if queue.empty():
                        async with asyncio.timeout(timeout):
                            item = await queue.get()
                    else:  # already here: no timer per packet (a big map is millions of packets)
                        item = queue.get_nowait()
                except TimeoutError:
                    raise self._no_reply(
                        f"{name!r} from {self.host}:{self.port} stalled for {timeout:g} s "
                        f"after {waiter.count} packets"
                    ) from None
                if item is None:
                    if waiter.error is not None:
                        raise waiter.error
                    return
                if self._conn is not None:
                    self._conn.reply_taken(waiter.reply, item)
                yield item
        finally:
            if not waiter.finished:
                self._abandon(waiter)

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
        name, payload = _request(what, args)
        waiter = self._start(name, payload, None, until, True, sys.maxsize, sys.maxsize, queued=False)
        if waiter is None:
            return 0
        try:
            while not waiter.finished:
                waiter.progress.clear()
                got = waiter.count
                try:
                    async with asyncio.timeout(timeout):
                        await waiter.progress.wait()
                except TimeoutError:
                    self._abandon(waiter)
                    raise self._no_reply(
                        f"{name!r} from {self.host}:{self.port} stalled for {timeout:g} s after {got} packets"
                        if got
                        else f"no reply to {name!r} from {self.host}:{self.port} within {timeout:g} s"
                    ) from None
                if progress is not None and waiter.count != got:
                    progress(waiter.count)
        finally:
            if not waiter.finished:
                self._abandon(waiter)
        if waiter.error is not None:
            raise waiter.error
        return waiter.count

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
    ) -> _Waiter | None:
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
        waiter = self._waiters[reply] = _Waiter(reply, streaming, queued=queued)
        return waiter

    def _abandon(self, waiter: _Waiter) -> None:
        """A waiter gave up: its slot stays so late packets still line up, but nobody waits on it."""
        self._waiters.pop(waiter.reply, None)
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
                if not self._on_events(self._conn.receive_data(data, now), now):
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

    def _on_events(self, events: Iterable[Event], now: float) -> bool:
        """Hand each event to its waiter and handler; False when the server shut down."""
        handlers, waiters = self._handlers, self._waiters
        woken: _Waiter | None = None
        for event in events:
            if isinstance(event, ReplyPacket):  # ahead of the rest: a map is a million of these
                reply, payload, swallowed = event
                if not swallowed:
                    waiter = waiters.get(reply)
                    if waiter is not None:  # _Waiter.packet, inlined: its wake-up once per read
                        waiter.count += 1
                        if waiter.queue is not None:
                            waiter.queue.put_nowait(payload)
                        if waiter is not woken:
                            waiter.progress.set()
                            woken = waiter
                if reply.number in handlers:
                    self._deliver(reply.number, reply.name, payload, now)
                else:
                    self.last_packet_at = now
                    self.packets_received += 1
            elif isinstance(event, DataReceived):
                self._deliver(event.command, event.name, event.payload, now)
            elif isinstance(event, ReplyComplete):
                waiter = self._waiters.pop(event.reply, None)
                if waiter is not None:
                    waiter.complete(event.payloads)
            elif isinstance(event, ReplyFailed):
                waiter = self._waiters.pop(event.reply, None)
                if waiter is not None:
                    too_large = event.reason is ReplyError.TOO_LARGE
                    error = ReplyTooLarge(event.message) if too_large else ProtocolFault(event.message)
                    waiter.fail(error, drop_unread=too_large)
            elif isinstance(event, PeerShutdown):
                return False
        return True

    def _deliver(self, number: int, name: str | None, payload: bytes, now: float) -> None:
        """One data packet: count it, and call the subscription handler of its data."""
        self.last_packet_at = now
        self.packets_received += 1
        handler = self._handlers.get(number)
        if handler is None:
            return
        started = time.perf_counter()
        started_cpu = time.thread_time()
        try:
            handler(Packet(name or str(number), payload, now))
        except Exception:
            self.handler_errors += 1
            log.exception("handler for %s failed", name)
        spent = time.perf_counter() - started
        cpu = time.thread_time() - started_cpu
        self.max_handler_seconds = max(self.max_handler_seconds, spent)
        self.max_handler_cpu_seconds = max(self.max_handler_cpu_seconds, cpu)
        if cpu > SLOW_HANDLER:
            self.slow_handlers_cpu += 1
        if spent > SLOW_HANDLER:  # it held up the loop that sends the stops: say so
            self.slow_handlers += 1
            if self.slow_handlers <= 10 or self.slow_handlers % 1000 == 0:
                # The CPU part tells slow work (ours to fix) from a machine that did not run us.
                log.warning(
                    "the handler for %s took %.0f ms on the network loop (%.0f ms of it on the CPU)",
                    name,
                    spent * 1e3,
                    cpu * 1e3,
                )

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
        waiters, self._waiters = self._waiters, {}
        for waiter in waiters.values():
            waiter.fail(error)
        if self._conn is not None:
            self._conn.replies.clear()
        self._handlers.clear()
        self._abort()

    def _abort(self) -> None:
        if self._link is not None:
            self._link.abort()

    async def flush(self, timeout: float = CLOSE_TIMEOUT) -> bool:
        """Wait, at most ``timeout`` s, until everything sent has been handed to the kernel.

        True when nothing is left in our buffer (``rtmu drive`` checks that its stop has left
        before the process is suspended). Never raises.
        """
        link = self._link
        if link is None or link.is_closing():
            return False
        loop = asyncio.get_running_loop()
        deadline = loop.time() + timeout
        with contextlib.suppress(TimeoutError, OSError):
            async with asyncio.timeout_at(deadline):
                await link.drain()
                while link.backlog() > 0:
                    await asyncio.sleep(0.005)
        return not link.is_closing() and link.backlog() == 0

    async def disconnect(self) -> None:
        """Say goodbye and close within :data:`CLOSE_TIMEOUT` s. Safe to call twice, or unconnected."""
        if self._closing:
            return
        self._closing = True
        task = self._read_task
        if task is not None and task is not asyncio.current_task():
            task.cancel()
        if self._conn is not None and self._link is not None and self._closed_error is None:
            self._conn.shutdown()
            data = self._conn.data_to_send()
            link = self._link
            if not link.is_closing():
                with contextlib.suppress(OSError):
                    link.write(data)
                    link.finish_writing()
                if task is not None and task is not asyncio.current_task():
                    await asyncio.wait({task}, timeout=CLOSE_TIMEOUT)  # the link has one reader at a time
                await _read_until_closed(link, LINGER_TIMEOUT)
                link.close()
                with contextlib.suppress(Exception):
                    await asyncio.wait_for(link.wait_closed(), CLOSE_TIMEOUT)
        self._teardown(ServerClosed("disconnected"))
        if task is not None and task is not asyncio.current_task() and not task.done():
            # Bounded: a reader that will not end must not keep the caller (a window closing) waiting.
            await asyncio.wait({task}, timeout=CLOSE_TIMEOUT)


async def _read_until_closed(link: Link, timeout: float) -> None:
    """Read and drop the peer's bytes until it closes (bounded): our socket then closes clean.

    Closing with the server's status still unread would reset the connection, and a server
    whose next write meets the reset can lose our goodbye unread — the stop with it.
    """
    with contextlib.suppress(Exception):
        async with asyncio.timeout(timeout):
            while await link.read(READ_CHUNK):
                pass


def _request(what: str | Payload, args: tuple[Arg, ...]) -> tuple[str, bytes]:
    """(data name, argument bytes) from a call's arguments; a typed payload names its own data."""
    if isinstance(what, Payload):
        if args:
            raise TypeError("a typed payload carries its own arguments")
        try:
            return named(what)
        except ProtocolError as exc:
            raise TypeError(str(exc)) from None
    return what, encode_args(args)


def login_rejected(conn: ClientConnection, event: Rejected) -> LoginRejected:
    """The refusal as the operator's error; reason 4 names the protocol string the server wants."""
    wanted = conn.wanted_protocol()
    advice = ""
    if event.reason == RejectReason.PROTOCOL_VERSION_MISMATCH and wanted is not None:
        advice = protocol_advice(wanted, conn.sent_protocol_version or "")
    return LoginRejected(event.reason, event.text, advice, wanted)

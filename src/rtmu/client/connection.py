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

Replies carry no request id in ArNetworking: a reply is matched to the oldest
pending request of the same data number (ARIA answers in order). A request whose
waiter gave up (timeout, cancel) is *abandoned*: its slot stays, so a late reply
still lines up with it and cannot be taken for the next request's. But a reply that
never comes must not shift every later reply by one for good, so an abandoned slot
that has received nothing is dropped as soon as a newer request of the same data is
sent (a reply later than its requester's whole timeout is treated as lost), and any
abandoned slot is dropped after :data:`ABANDON_GRACE` s without a packet (a map that
stalled half way). At most :data:`MAX_PENDING_PER_DATA` requests per data number
wait at once.

Everything here runs on one asyncio loop (the network thread's, see
``runner``); handlers are called on that loop and must be quick.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import socket
import time
from collections import deque
from collections.abc import AsyncIterator, Callable
from dataclasses import dataclass, field

from ..protocol.client_connection import ClientConnection, ClientState, protocol_advice
from ..protocol.commands import RejectReason
from ..protocol.datalist import DataList
from ..protocol.decoder import DropStats
from ..protocol.errors import ProtocolError
from ..protocol.events import DataListReady, DataReceived, PeerShutdown, Rejected
from ..protocol.fields import FieldWriter
from ..protocol.packet import MAX_LENGTH
from ..protocol.payloads import Payload, Side, decode_payload
from ..protocol.payloads.mapstream import MapTooLarge
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

log = logging.getLogger(__name__)

DEFAULT_PORT = 7272
CONNECT_TIMEOUT = 10.0
"""ARIA's own client gives up connecting after 10 s."""
REPLY_TIMEOUT = 5.0
"""Default wait for a reply, and for each further packet of a multi-packet reply."""
CLOSE_TIMEOUT = 0.2
"""How long ``disconnect`` lets the goodbye flush before cutting the socket."""
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
MAX_REPLY_PACKETS = 1_000_000
"""Default bound on the packets of one collected reply (``request_once``) or of a stream's unread ones."""
MAX_REPLY_BYTES = 64 << 20
"""Default bound on the payload bytes of one collected reply, or of a stream's unread packets."""
ABANDON_GRACE = 0.5
"""Seconds an abandoned request's slot waits quietly for a late reply before the reply counts as lost."""
MAX_PENDING_PER_DATA = 64
"""Requests of one data number that may wait for replies at once (abandoned slots included)."""

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


# -- how a reply ends -----------------------------------------------------------------------------
# ArNetworking has no end-of-reply framing; each data has its own pattern (protocol §3.7, §4.5).


class _EndRule:
    """Decides, packet by packet, whether a reply is complete."""

    def done(self, payload: bytes, count_before: int) -> bool:
        raise NotImplementedError


class _Single(_EndRule):
    def __init__(self, n: int = 1) -> None:
        self.n = n

    def done(self, payload: bytes, count_before: int) -> bool:
        return count_before + 1 >= self.n


class _UntilEmpty(_EndRule):
    """RETURN_UNTIL_EMPTY: a zero-length packet ends the series."""

    def done(self, payload: bytes, count_before: int) -> bool:
        return not payload


class _Until(_EndRule):
    """The caller's own end test (a map assembler's ``feed``)."""

    def __init__(self, until: Callable[[bytes], bool]) -> None:
        self.until = until

    def done(self, payload: bytes, count_before: int) -> bool:
        return self.until(payload)


class _MapStream(_EndRule):
    """``getMap``/``getMapBinary``: ends with a zero-length packet, or at once with one ``00`` (no map)."""

    def done(self, payload: bytes, count_before: int) -> bool:
        return not payload or (count_before == 0 and payload == b"\x00")


_MAP_STREAMS = frozenset({"getMap", "getMapBinary", "getMapMultiScans", "getMapWithMaxCategory"})


def _end_rule(
    entry_flags: frozenset[str], name: str, expect: int | None, until: Callable[[bytes], bool] | None
) -> _EndRule | None:
    """None = the data has no reply (RETURN_NONE)."""
    if until is not None:
        return _Until(until)
    if expect is not None:
        return _Single(expect)
    if name in _MAP_STREAMS:
        return _MapStream()
    if name == "popupList" or "RETURN_UNTIL_EMPTY" in entry_flags:
        return _UntilEmpty()
    if "RETURN_NONE" in entry_flags:
        return None
    return _Single()


class _Pending:
    """One request waiting for its reply packets (one slot in its data number's queue).

    A waiter that gives up (timeout, cancel, a stream closed early) *abandons* the slot: it
    stays so that a late reply still lines up with it, and swallows that reply's packets
    (to the data's own end marker) without keeping them. See the module notes for when an
    abandoned slot is dropped.

    What the slot holds is bounded: a collected reply by ``max_packets``/``max_bytes`` in all,
    a streamed one by the packets/bytes its reader has not taken yet (each payload is held
    once: in the list, or in the stream's queue). Past a bound the waiter gets
    :class:`ReplyTooLarge` and the slot swallows the rest of the reply.
    """

    __slots__ = (
        "abandoned_at",
        "count",
        "error",
        "fallback",
        "finished",
        "held_bytes",
        "last_activity",
        "max_bytes",
        "max_packets",
        "name",
        "payloads",
        "progress",
        "queue",
        "rule",
    )

    def __init__(
        self,
        name: str,
        rule: _EndRule,
        streaming: bool,
        fallback: _EndRule | None = None,
        *,
        max_packets: int = MAX_REPLY_PACKETS,
        max_bytes: int = MAX_REPLY_BYTES,
    ) -> None:
        self.name = name
        self.rule = rule
        self.fallback = fallback or rule
        """Where the reply ends without the caller's own test (used once the caller is gone)."""
        self.payloads: list[bytes] = []
        self.count = 0
        self.held_bytes = 0
        """Bytes held for the waiter: all of them (collected), or those not read yet (streamed)."""
        self.max_packets = max_packets
        self.max_bytes = max_bytes
        self.queue: asyncio.Queue[bytes | None] | None = asyncio.Queue() if streaming else None
        self.progress = asyncio.Event()
        self.finished = False
        self.error: ClientError | None = None
        self.abandoned_at: float | None = None
        self.last_activity = 0.0

    def feed(self, payload: bytes, now: float) -> bool:
        """One packet of this reply; True when the slot is done (take it off the queue)."""
        if self.abandoned_at is not None:
            return self._swallow(payload, now)
        if self.finished:
            return True
        try:
            finished = self.rule.done(payload, self.count)
        except MapTooLarge as exc:  # more than any map can be: an endless or hostile stream
            self.fail(ProtocolFault(f"the server's map is too large, download stopped: {exc}"))
            return True
        except ProtocolError as exc:  # the caller's end test found the reply malformed
            self.fail(ProtocolFault(f"malformed reply: {exc}"))
            return True
        self.count += 1
        self.finished = finished
        self.held_bytes += len(payload)
        if self.queue is not None:
            self.queue.put_nowait(payload)
            held_packets = self.queue.qsize()
            if finished:
                self.queue.put_nowait(None)
        else:
            self.payloads.append(payload)
            held_packets = len(self.payloads)
        if not finished and (held_packets > self.max_packets or self.held_bytes > self.max_bytes):
            self._overflow(held_packets > self.max_packets, now)
            return False
        self.progress.set()
        return finished

    def taken(self, payload: bytes) -> None:
        """A stream's reader took ``payload``: it is no longer held here."""
        self.held_bytes -= len(payload)

    def _overflow(self, by_count: bool, now: float) -> None:
        limit = f"{self.max_packets} packets" if by_count else f"{self.max_bytes} bytes"
        waiting = "not read yet" if self.queue is not None else "in one reply"
        if self.queue is not None:
            while not self.queue.empty():  # the reader gets the error next, not stale packets first
                self.queue.get_nowait()
        self.abandon(ReplyTooLarge(f"more than {limit} of {self.name!r} {waiting}; the rest is dropped"), now)

    def _swallow(self, payload: bytes, now: float) -> bool:
        self.last_activity = now
        try:
            done = self.fallback.done(payload, self.count)
        except ProtocolError:
            done = True
        self.count += 1
        return done

    def abandon(self, error: ClientError, now: float) -> None:
        """The waiter is gone (or must stop waiting): fail it, keep the slot for the rest of the reply."""
        self.fail(error)
        self.abandoned_at = self.last_activity = now
        self.payloads = []
        self.held_bytes = 0

    def expired(self, now: float, grace: float) -> bool:
        return self.abandoned_at is not None and now - self.last_activity >= grace

    def fail(self, error: ClientError) -> None:
        if self.finished:
            return
        self.finished = True
        self.error = error
        if self.queue is not None:
            self.queue.put_nowait(None)
        self.progress.set()


class AriaClient:
    """One connection. Create, ``await connect(...)``, use, ``await disconnect()``.

    ``on_close(error)`` is called once when the connection ends for any reason
    other than :meth:`disconnect` (``error`` says why, e.g. :class:`ServerClosed`).
    """

    def __init__(
        self,
        *,
        on_close: Callable[[ClientError], None] | None = None,
        clock: Callable[[], float] = time.monotonic,
        abandon_grace: float = ABANDON_GRACE,
    ) -> None:
        self.on_close = on_close
        self.clock = clock
        self.abandon_grace = abandon_grace
        self.max_pending = MAX_PENDING_PER_DATA
        self.host = ""
        self.port = 0
        self.user = ""
        self._conn: ClientConnection | None = None
        self._reader: asyncio.StreamReader | None = None
        self._writer: asyncio.StreamWriter | None = None
        self._read_task: asyncio.Task[None] | None = None
        self._handlers: dict[int, Handler] = {}
        self._pending: dict[int, deque[_Pending]] = {}
        self._closed_error: ClientError | None = None
        self._closing = False
        self.handler_errors = 0
        """Exceptions raised by subscription handlers (logged, never fatal)."""
        self.slow_handlers = 0
        """Handler calls that took longer than :data:`SLOW_HANDLER` (logged: they delay every packet)."""
        self.max_handler_seconds = 0.0
        """The longest one handler call has held the loop (soak and health figures)."""
        self.last_packet_at: float | None = None
        self.packets_received = 0

    # -- state -----------------------------------------------------------------------------
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
    def drops(self) -> DropStats:
        """What the decoder threw away on this connection (bad checksums, garbage bytes…)."""
        return self._conn.decoder.stats if self._conn is not None else DropStats()

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
    ) -> DataList:
        """Open the socket, log in and wait for the complete data list, all within ``timeout`` s."""
        if self._conn is not None:
            raise RuntimeError("AriaClient objects are single-use: make a new one to connect again")
        self.host, self.port, self.user = host, port, user or ""
        self._conn = ClientConnection(
            user or "", password or "", server_key=server_key, protocol_version=protocol
        )
        deadline = asyncio.get_running_loop().time() + timeout
        try:
            async with asyncio.timeout_at(deadline):
                self._reader, self._writer = await asyncio.open_connection(host, port)
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
        sock = self._writer.get_extra_info("socket")
        if sock is not None:
            with contextlib.suppress(OSError):
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
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
        assert self._reader is not None and self._conn is not None
        received = 0
        while True:
            try:
                data = await self._reader.read(READ_CHUNK)
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
            try:
                events = self._conn.receive_data(data)
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
                    self._dispatch(event)
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
        self._handlers[number] = handler
        self._conn.request(name, interval_ms, encode_args(args))  # type: ignore[union-attr]
        self._flush()

    def stop_request(self, name: str) -> None:
        """End a subscription (no reply). Unknown or unsubscribed names are ignored."""
        number = self._conn.datalist.number(name) if self._conn is not None else None
        if number is None or not self.connected:
            return
        self._handlers.pop(number, None)
        self._conn.request_stop(name)  # type: ignore[union-attr]
        self._flush()

    def send(self, name: str, *args: Arg) -> None:
        """Run ``name`` once without waiting for anything (``stop``, ``ratioDrive``, ``turnByAngle``…)."""
        self._number(name)
        self._conn.request_once(name, encode_args(args))  # type: ignore[union-attr]
        self._flush()

    async def request_once(
        self,
        name: str,
        *args: Arg,
        timeout: float = REPLY_TIMEOUT,
        expect: int | None = None,
        until: Callable[[bytes], bool] | None = None,
        max_packets: int = MAX_REPLY_PACKETS,
        max_bytes: int = MAX_REPLY_BYTES,
    ) -> Reply:
        """Run ``name`` once and await its reply.

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
        pending = self._start(name, args, expect, until, False, max_packets, max_bytes)
        if pending is None:
            return Reply(name, (), self.clock())
        try:
            while not pending.finished:
                pending.progress.clear()
                try:
                    async with asyncio.timeout(timeout):
                        await pending.progress.wait()
                except TimeoutError:
                    got = pending.count
                    self._abandon(name, pending)
                    raise self._no_reply(
                        f"no reply to {name!r} from {self.host}:{self.port} within {timeout:g} s"
                        + (f" (after {got} packets)" if got else "")
                    ) from None
        finally:
            if not pending.finished:  # cancelled: the slot must not wait for ever either
                self._abandon(name, pending)
        if pending.error is not None:
            raise pending.error
        return Reply(name, tuple(pending.payloads), self.clock())

    async def stream(
        self,
        name: str,
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
        pending = self._start(name, args, expect, until, True, max_packets, max_bytes)
        if pending is None:
            return
        queue = pending.queue
        assert queue is not None
        try:
            while True:
                try:
                    if queue.empty():
                        async with asyncio.timeout(timeout):
                            payload = await queue.get()
                    else:  # already here: no timer per packet (a big map is millions of packets)
                        payload = queue.get_nowait()
                except TimeoutError:
                    raise self._no_reply(
                        f"{name!r} from {self.host}:{self.port} stalled for {timeout:g} s "
                        f"after {pending.count} packets"
                    ) from None
                if payload is None:
                    if pending.error is not None:
                        raise pending.error
                    return
                pending.taken(payload)
                yield payload
        finally:
            if not pending.finished:
                self._abandon(name, pending)

    def _start(
        self,
        name: str,
        args: tuple[Arg, ...],
        expect: int | None,
        until: Callable[[bytes], bool] | None,
        streaming: bool,
        max_packets: int = MAX_REPLY_PACKETS,
        max_bytes: int = MAX_REPLY_BYTES,
    ) -> _Pending | None:
        number = self._number(name)
        entry = self._conn.datalist.entry(number)  # type: ignore[union-attr]
        flags = entry.flag_set if entry else frozenset()
        rule = _end_rule(flags, name, expect, until)
        payload = encode_args(args)
        if rule is None:
            self._conn.request_once(name, payload)  # type: ignore[union-attr]
            self._flush()
            return None
        queue = self._pending.setdefault(number, deque())
        self._expire(queue, self.clock(), newer_request=True)
        while len(queue) >= self.max_pending and queue[0].abandoned_at is not None:
            queue.popleft()  # make room: the oldest abandoned slot goes first
        if len(queue) >= self.max_pending:
            raise ClientError(
                f"{len(queue)} requests for {name!r} are already waiting for {self.host}:{self.port} "
                "to answer; not sending more"
            )
        fallback = _end_rule(flags, name, expect, None)
        pending = _Pending(name, rule, streaming, fallback, max_packets=max_packets, max_bytes=max_bytes)
        queue.append(pending)
        self._conn.request_once(name, payload)  # type: ignore[union-attr]
        self._flush()
        return pending

    def _abandon(self, name: str, pending: _Pending) -> None:
        """A waiter gave up: keep its slot so late packets still line up, but stop caring."""
        pending.abandon(ClientTimeout(f"{name!r} abandoned"), self.clock())

    def _expire(self, queue: deque[_Pending], now: float, *, newer_request: bool = False) -> None:
        """Drop abandoned slots at the head whose replies count as lost (see the module notes)."""
        while queue:
            head = queue[0]
            if head.abandoned_at is None:
                return
            if not (head.expired(now, self.abandon_grace) or (newer_request and head.count == 0)):
                return
            queue.popleft()

    # -- I/O -------------------------------------------------------------------------------
    def _flush(self) -> None:
        if self._conn is None or self._writer is None:
            return
        data = self._conn.data_to_send()
        if not data or self._writer.is_closing():
            return
        self._writer.write(data)
        if self._writer.transport.get_write_buffer_size() > MAX_WRITE_BUFFER:
            self._fail(ServerClosed(f"{self.host}:{self.port} stopped reading; the connection was dropped"))

    async def _read_loop(self) -> None:
        assert self._reader is not None and self._conn is not None
        try:
            while True:
                data = await self._reader.read(READ_CHUNK)
                if not data:
                    self._fail(ServerClosed(f"{self.host}:{self.port} closed the connection"))
                    return
                for event in self._conn.receive_data(data):
                    if isinstance(event, DataReceived):
                        self._dispatch(event)
                    elif isinstance(event, PeerShutdown):
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

    def _dispatch(self, event: DataReceived) -> None:
        now = self.clock()
        self.last_packet_at = now
        self.packets_received += 1
        number = event.command
        queue = self._pending.get(number)
        if queue:
            self._expire(queue, now)
            if queue and queue[0].feed(event.payload, now):
                queue.popleft()
        handler = self._handlers.get(number)
        if handler is not None:
            started = time.perf_counter()
            try:
                handler(Packet(event.name or str(number), event.payload, now))
            except Exception:
                self.handler_errors += 1
                log.exception("handler for %s failed", event.name)
            spent = time.perf_counter() - started
            self.max_handler_seconds = max(self.max_handler_seconds, spent)
            if spent > SLOW_HANDLER:  # it held up the loop that sends the stops: say so
                self.slow_handlers += 1
                if self.slow_handlers <= 10 or self.slow_handlers % 1000 == 0:
                    log.warning(
                        "the handler for %s took %.0f ms on the network loop", event.name, spent * 1e3
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
        for queue in self._pending.values():
            for pending in queue:
                pending.fail(error)
        self._pending.clear()
        self._handlers.clear()
        self._abort()

    def _abort(self) -> None:
        if self._writer is not None:
            transport = self._writer.transport
            if not transport.is_closing():
                transport.abort()

    async def flush(self, timeout: float = CLOSE_TIMEOUT) -> bool:
        """Wait, at most ``timeout`` s, until everything sent has been handed to the kernel.

        True when nothing is left in our buffer (``rtmu drive`` checks that its stop has left
        before the process is suspended). Never raises.
        """
        writer = self._writer
        if writer is None or writer.is_closing():
            return False
        loop = asyncio.get_running_loop()
        deadline = loop.time() + timeout
        with contextlib.suppress(TimeoutError, OSError):
            async with asyncio.timeout_at(deadline):
                await writer.drain()
                while writer.transport.get_write_buffer_size() > 0:
                    await asyncio.sleep(0.005)
        return not writer.is_closing() and writer.transport.get_write_buffer_size() == 0

    async def disconnect(self) -> None:
        """Say goodbye and close within :data:`CLOSE_TIMEOUT` s. Safe to call twice, or unconnected."""
        if self._closing:
            return
        self._closing = True
        task = self._read_task
        if task is not None and task is not asyncio.current_task():
            task.cancel()
        if self._conn is not None and self._writer is not None and self._closed_error is None:
            self._conn.shutdown()
            data = self._conn.data_to_send()
            writer = self._writer
            if not writer.is_closing():
                with contextlib.suppress(OSError):
                    writer.write(data)
                writer.close()
                with contextlib.suppress(Exception):
                    await asyncio.wait_for(writer.wait_closed(), CLOSE_TIMEOUT)
        self._teardown(ServerClosed("disconnected"))
        if task is not None and task is not asyncio.current_task() and not task.done():
            # Bounded: a reader that will not end must not keep the caller (a window closing) waiting.
            await asyncio.wait({task}, timeout=CLOSE_TIMEOUT)


def login_rejected(conn: ClientConnection, event: Rejected) -> LoginRejected:
    """The refusal as the operator's error; reason 4 names the protocol string the server wants."""
    wanted = conn.wanted_protocol()
    advice = ""
    if event.reason == RejectReason.PROTOCOL_VERSION_MISMATCH and wanted is not None:
        advice = protocol_advice(wanted, conn.sent_protocol_version or "")
    return LoginRejected(event.reason, event.text, advice, wanted)

"""One client of the simulator's server: its codec, its subscriptions, its socket.

Split from :mod:`.server` so that the server's cycle and a client's reading and writing each fit
in a module: a client decodes its own bytes a slice at a time, is sent big downloads only as fast
as it reads them, and is dropped when it stops draining; the server only steps the world and
invokes handlers for it.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from dataclasses import dataclass
from typing import Protocol

from rtmu.protocol.commands import RejectReason
from rtmu.protocol.events import (
    ClientIntroduced,
    LoginRefused,
    PeerShutdown,
    RequestOnce,
    RequestReceived,
    RequestStopped,
)
from rtmu.protocol.packet import encode_packet
from rtmu.protocol.payloads.control import ClientIntroduction
from rtmu.protocol.server_connection import ServerConnection, ServerState

from .config import SimConfig
from .handlers import (
    BROADCAST_ONLY,
)
from .heard import RequestLog
from .mapserve import Chunks
from .world import World

log = logging.getLogger("rtmu.sim")

READ_CHUNK = 65536
"""Bytes read from a client's socket at a time."""
RECEIVE_SLICE = 4096
"""At most this many bytes of one client's input are decoded and handled before the loop turns, so a
client that floods (garbage, fake headers, a burst of requests) cannot hold up the cycle or the others."""
SMALL_STREAM_BYTES = 256 * 1024
"""A download this small is written at once, in order with the replies around it; a bigger one is
sent a chunk at a time as the client reads it, so no client ever has a whole big map queued."""


class ClientHost(Protocol):
    """What a client needs of the server that accepted it (the server implements it; no import back)."""

    config: SimConfig
    world: World
    heard: RequestLog
    malformed_packets: int

    def forget(self, session: SimClient) -> None: ...

    def invoke(self, session: SimClient, number: int, name: str, args: bytes, *, once: bool) -> None: ...

    def broadcast_changes(self) -> None: ...

    def clock(self) -> float: ...


class SimServerConnection(ServerConnection):
    """ARIA's other refusals on top of the codec's user check: central server, too many clients,
    protocol version and client type (reasons 2, 5, 4, 6). A simulator refuses and closes."""

    def __init__(self, *args, general_reject: tuple[int, str] | None = None, config: SimConfig, **kw) -> None:
        super().__init__(*args, **kw)
        self._general_reject = general_reject
        self._config = config

    def _refusal(self, intro: ClientIntroduction | None) -> LoginRefused | None:
        if self._general_reject is not None:
            reason, text = self._general_reject
            return self.reject(RejectReason(reason), text)
        # An introduction that does not decode carries no version and no type: ARIA reads "" and 0.
        version, client_type = ("", 0) if intro is None else (intro.protocol_version, intro.client_type)
        enforced = self._config.protocol_version
        cfg = self._config
        if enforced is not None and version != enforced:
            return self.reject(
                RejectReason.PROTOCOL_VERSION_MISMATCH,
                "Server rejecting client connection since protocol version does not match",
            )
        if cfg.client_type is not None and (client_type != cfg.client_type or cfg.client_type == 3):
            return self.reject(
                RejectReason.CLIENT_TYPE_MISMATCH,
                "Server rejecting client connection since type (real or sim) does not match "
                "(but is specified)",
            )
        return super()._refusal(intro)


@dataclass(slots=True)
class Subscription:
    name: str
    interval_ms: int
    args: bytes
    last: float


class SimClient:
    """One connected client: its codec, its subscriptions, its socket."""

    def __init__(
        self,
        server: ClientHost,
        ident: int,
        reader: asyncio.StreamReader,
        writer: asyncio.StreamWriter,
        conn: SimServerConnection,
    ) -> None:
        self.server = server
        self.ident = ident
        self.reader = reader
        self.writer = writer
        self.conn = conn
        self.subscriptions: dict[int, Subscription] = {}
        self.accepted_at = server.clock()
        self.closed = False
        self.self_identifier = ""
        self.here_goal = ""
        self._stall_since: float | None = None
        self._last_buffered = 0
        self.bytes_out = 0
        self.bytes_in = 0
        self._download: asyncio.Task[None] | None = None
        self._queued_downloads: dict[int, Chunks] = {}
        peer = writer.get_extra_info("peername")
        self.peer = f"{peer[0]}:{peer[1]}" if isinstance(peer, tuple) else str(peer)

    # -- output -----------------------------------------------------------------------
    @property
    def buffered(self) -> int:
        transport = self.writer.transport
        return 0 if transport is None or transport.is_closing() else transport.get_write_buffer_size()

    def write(self, data: bytes) -> None:
        if self.closed or not data:
            return
        if self.buffered + len(data) > self.server.config.max_queued_bytes:
            log.info("client %s: %d bytes queued and not read; dropping it", self.peer, self.buffered)
            self.abort()
            return
        try:
            self.writer.write(data)
            self.bytes_out += len(data)
        except (ConnectionError, RuntimeError, OSError):
            self.abort()

    def stream(self, number: int, chunks: Chunks) -> None:
        """Send a download (a map): one at a time per client, a chunk at a time as the client reads.

        A download asked for while another is being sent waits for it; asking again for one that is
        already waiting does not queue a second copy (the client gets it once, the newest version).
        """
        if self.closed:
            return
        if self._download is not None:
            if number in self._queued_downloads:
                log.info("client %s: map %d asked for again while queued; sending it once", self.peer, number)
            self._queued_downloads[number] = chunks
            return
        if sum(len(c) for c in chunks) <= SMALL_STREAM_BYTES:
            for chunk in chunks:
                self.write(chunk)
            return
        self._download = asyncio.get_running_loop().create_task(self._send_downloads(chunks))

    async def _send_downloads(self, chunks: Chunks) -> None:
        try:
            while True:
                for chunk in chunks:
                    if self.closed:
                        return
                    self.write(chunk)
                    await self.writer.drain()  # waits while more than 64 KiB is queued for this client
                    await asyncio.sleep(0)
                if not self._queued_downloads or self.closed:
                    return
                chunks = self._queued_downloads.pop(next(iter(self._queued_downloads)))
        except (ConnectionError, OSError, RuntimeError):
            self.abort()
        finally:
            if self._download is asyncio.current_task():
                self._download = None
                self._queued_downloads.clear()

    def cancel_download(self) -> None:
        self._queued_downloads.clear()
        task, self._download = self._download, None
        if task is not None and task is not asyncio.current_task():
            task.cancel()

    def flush_codec(self) -> None:
        self.write(self.conn.data_to_send())

    def send(self, number: int, payload: bytes) -> None:
        self.write(encode_packet(number, payload))

    def may_use(self, group: str) -> bool:
        user = self.conn.user
        return True if user is None else user.may_use(group)

    # -- lifetime ---------------------------------------------------------------------
    def abort(self) -> None:
        """Gone: no goodbye, just close (a vanished client, a slow one, a killed server)."""
        if self.closed:
            return
        self.closed = True
        self.cancel_download()
        transport = self.writer.transport
        if transport is not None:
            transport.abort()
        self.server.forget(self)

    def close_after_flush(self, delay: float = 0.02) -> None:
        if self.closed:
            return
        self.closed = True
        self.cancel_download()
        self.server.forget(self)

        def finish() -> None:
            with contextlib.suppress(Exception):
                self.writer.close()

        asyncio.get_running_loop().call_later(delay, finish)

    def check_health(self, now_real: float) -> None:
        """Intro deadline and ARIA's backup timeout (queued output that does not move)."""
        cfg = self.server.config
        if (
            self.conn.state is ServerState.SENT_INTRODUCTION
            and now_real - self.accepted_at > cfg.intro_timeout
        ):
            self.abort()
            return
        size = self.buffered
        if size == 0 or size < self._last_buffered:
            self._stall_since = None
        elif self._stall_since is None:
            self._stall_since = now_real
        elif now_real - self._stall_since > cfg.backup_timeout:
            log.info("client %s: output stuck for %.0f s; dropping it", self.peer, cfg.backup_timeout)
            self.abort()
        self._last_buffered = size

    async def run(self) -> None:
        self.flush_codec()  # the server INTRODUCTION
        try:
            while not self.closed:
                data = await self.reader.read(READ_CHUNK)
                if not data:
                    break
                view = memoryview(data)
                for start in range(0, len(data), RECEIVE_SLICE):
                    piece = bytes(view[start : start + RECEIVE_SLICE])
                    self.bytes_in += len(piece)
                    self.receive(piece)
                    if self.closed:
                        break
                    # A read that finds bytes already buffered does not yield: let the others run.
                    await asyncio.sleep(0)
        except (ConnectionError, OSError, asyncio.IncompleteReadError):
            pass
        except asyncio.CancelledError:
            raise
        except Exception:  # a bug must cost this client only
            log.exception("client %s: handler failed; closing it", self.peer)
        finally:
            self.abort()

    def receive(self, data: bytes) -> None:
        malformed = self.conn.malformed_packets
        events = self.conn.receive_data(data)
        if self.conn.malformed_packets != malformed:
            # Decoded as typed errors by the codec: a bad INTRODUCTION is refused, a bad REQUEST ignored.
            self.server.malformed_packets += self.conn.malformed_packets - malformed
            log.info("client %s: %d malformed control packet(s)", self.peer, self.conn.malformed_packets)
        for event in events:
            if isinstance(event, (RequestOnce, RequestReceived)):
                once = isinstance(event, RequestOnce)
                self.server.heard.note(self.server.world.time, self.ident, self.peer, event.name, once=once)
            if isinstance(event, RequestOnce):
                self.server.invoke(self, event.number, event.name, event.args, once=True)
            elif isinstance(event, RequestReceived):
                self._on_request(event)
            elif isinstance(event, RequestStopped):
                self.subscriptions.pop(event.number, None)
            elif isinstance(event, ClientIntroduced):
                self.flush_codec()
                log.info("client %s logged in as %r", self.peer, event.user)
            elif isinstance(event, LoginRefused):
                self.flush_codec()
                log.info("client %s refused (reason %d)", self.peer, event.reason)
                self.close_after_flush()
                return
            elif isinstance(event, PeerShutdown):
                self.abort()
                return
            if self.closed:
                return
        self.flush_codec()
        self.server.broadcast_changes()  # what a request changed (mode, popups) goes out now, as in ARIA

    def _on_request(self, event: RequestReceived) -> None:
        now = self.server.world.time
        sub = self.subscriptions.get(event.number)
        if sub is not None:
            sub.interval_ms, sub.args = event.interval_ms, event.args
            return
        self.subscriptions[event.number] = Subscription(event.name, event.interval_ms, event.args, now)
        if event.name not in BROADCAST_ONLY:
            self.server.invoke(self, event.number, event.name, event.args, once=True)

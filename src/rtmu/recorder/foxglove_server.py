"""The Foxglove WebSocket protocol, served by RTMU itself on the ``websockets`` package.

foxglove-sdk's own server accepts every handshake it can parse: it checks no Origin, no Host and
no token, speaks only ``foxglove.sdk.v1``, and cannot tell one client apart from another. The
bridge needs all four (:mod:`.foxglove_gate`, one driver at a time, the others told), so it serves
the protocol here, from its published specification: JSON ``serverInfo`` / ``advertise`` /
``status`` and binary message data to the clients; ``subscribe`` / ``unsubscribe`` and, only
where the bridge lets clients publish, client ``advertise`` / ``unadvertise`` and binary client
message data from them. Messages stay foxglove-sdk's (its schemas and their protobuf encoding).

Everything runs on one asyncio loop on a thread of its own; :meth:`FoxgloveServer.channel`,
:meth:`~FoxgloveServer.log` and :meth:`~FoxgloveServer.close` may be called from any thread.
Everything is bounded: clients (:data:`MAX_CLIENTS`), what a client may send (:data:`MAX_CLIENT_MESSAGE`
bytes, :data:`MAX_CLIENT_CHANNELS`), what waits for a slow client (:data:`MAX_PENDING_BYTES`: the
oldest data is dropped and counted; control messages are never dropped), and what waits for the loop
(:data:`MAX_INBOX`). The latest message of each kept channel is sent at once to a client that
subscribes later, so a Foxglove opened on a parked robot still shows where it stands.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import struct
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

from websockets.asyncio.server import Server, ServerConnection, serve
from websockets.exceptions import ConnectionClosed
from websockets.http11 import Request, Response

from .foxglove_gate import SUBPROTOCOLS, Gate

log = logging.getLogger(__name__)

MAX_CLIENTS = 16
MAX_CLIENT_MESSAGE = 64 * 1024
"""A client sends subscriptions and drive messages: nothing bigger (the connection is closed)."""
MAX_CLIENT_CHANNELS = 64
MAX_SUBSCRIPTIONS = 1024
MAX_PENDING_BYTES = 16 * 1024 * 1024
"""What may wait for one slow client; beyond it its oldest data messages are dropped."""
MAX_INBOX = 4096
"""Messages waiting for the loop (from the bridge's worker); beyond it new ones are dropped and counted."""
TELL_EVERY = 1.0
"""Seconds between two status messages of the same text to one client."""
OP_MESSAGE_DATA = 1
STATUS_INFO, STATUS_WARNING, STATUS_ERROR = 0, 1, 2
_DATA = struct.Struct("<BIQ")
_CLIENT_DATA = struct.Struct("<BI")


@dataclass(frozen=True, slots=True)
class ServerChannel:
    id: int
    topic: str
    encoding: str
    schema_name: str
    schema: str
    """The schema as the protocol carries it: JSON Schema text, or a base64 protobuf FileDescriptorSet."""
    schema_encoding: str
    keep: bool
    """A client that subscribes later gets this channel's latest message at once."""

    def advertisement(self) -> dict[str, Any]:
        return {
            "id": self.id,
            "topic": self.topic,
            "encoding": self.encoding,
            "schemaName": self.schema_name,
            "schema": self.schema,
            "schemaEncoding": self.schema_encoding,
        }


@dataclass(frozen=True, slots=True)
class ClientChannel:
    """A channel a client advertised to publish on."""

    id: int
    topic: str
    encoding: str
    schema_name: str


class ClientListener(Protocol):
    """What the bridge hears of clients that publish (only where it lets them: ``client_publish``)."""

    def advertised(self, client: int, channel: ClientChannel) -> None: ...

    def unadvertised(self, client: int, channel: ClientChannel) -> None: ...

    def message(self, client: int, channel: ClientChannel, data: bytes) -> str | None:
        """None: taken; else the sentence the client is told (as a warning status)."""
        ...

    def gone(self, client: int) -> None: ...


@dataclass(eq=False)
class _Client:
    id: int
    ws: ServerConnection
    subscriptions: dict[int, int] = field(default_factory=dict)
    """Subscription id → channel id."""
    by_channel: dict[int, int] = field(default_factory=dict)
    """Channel id → subscription id."""
    publishing: dict[int, ClientChannel] = field(default_factory=dict)
    out: deque[tuple[str | bytes, bool]] = field(default_factory=deque)
    """Frames waiting to be sent, with whether they may be dropped (data) or not (control)."""
    out_bytes: int = 0
    dropped: int = 0
    told: dict[str, float] = field(default_factory=dict)
    wake: asyncio.Event = field(default_factory=asyncio.Event)

    def push(self, frame: str | bytes, droppable: bool) -> None:
        self.out.append((frame, droppable))
        self.out_bytes += len(frame)
        while self.out_bytes > MAX_PENDING_BYTES:
            oldest = next((i for i, (_, d) in enumerate(self.out) if d), None)
            if oldest is None:
                break
            frame_dropped, _ = self.out[oldest]
            del self.out[oldest]
            self.out_bytes -= len(frame_dropped)
            self.dropped += 1
        self.wake.set()


class FoxgloveServer:
    """``FoxgloveServer(host=…, port=…, gate=…).start()``; ``channel(…)`` then ``log(…)`` from any thread."""

    def __init__(
        self,
        *,
        host: str = "127.0.0.1",
        port: int = 8765,
        gate: Gate | None = None,
        name: str = "rtmu",
        listener: ClientListener | None = None,
    ) -> None:
        self.host = host
        self.requested_port = port
        self.gate = gate or Gate()
        self.name = name
        self.listener = listener
        """None: clients may not publish (no ``clientPublish`` capability, their messages refused)."""
        self.on_refused: Callable[[str], None] | None = None
        """Told (on the server's thread) why a handshake was refused, for the operator."""
        self.refused = 0
        self.dropped = 0
        """Messages dropped: the loop behind (inbox full) or a slow client's oldest data."""
        self._channels: dict[int, ServerChannel] = {}
        self._by_topic: dict[str, ServerChannel] = {}
        self._kept: dict[int, tuple[bytes, int]] = {}
        self._clients: dict[int, _Client] = {}
        self._next_client = 1
        self._lock = threading.Lock()
        self._inbox: deque[tuple[int, bytes, int]] = deque()
        self._drain_scheduled = False
        self._session = str(time.time_ns())
        self._loop: asyncio.AbstractEventLoop | None = None
        self._server: Server | None = None
        self._stopping: asyncio.Event | None = None
        self._ready = threading.Event()
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, name="rtmu-foxglove", daemon=True)
        self._port = 0

    # -- any thread ------------------------------------------------------------------------------
    @property
    def port(self) -> int:
        return self._port

    @property
    def clients(self) -> int:
        return len(self._clients)

    def start(self) -> FoxgloveServer:
        """Listen; raises ``OSError`` when the address cannot be had."""
        self._thread.start()
        self._ready.wait(10.0)
        if self._error is not None:
            self._thread.join(2.0)
            raise self._error
        if not self._ready.is_set():
            raise OSError("the Foxglove server did not start")
        return self

    def close(self, timeout: float = 3.0) -> None:
        loop, stopping = self._loop, self._stopping
        if loop is not None and stopping is not None and self._thread.is_alive():
            with contextlib.suppress(RuntimeError):
                loop.call_soon_threadsafe(stopping.set)
            self._thread.join(timeout)

    def channel(
        self, topic: str, *, encoding: str, schema_name: str, schema: str, schema_encoding: str, keep: bool
    ) -> int:
        """The id of ``topic``'s channel, advertised to every client (made on first use)."""
        with self._lock:
            known = self._by_topic.get(topic)
            if known is not None:
                return known.id
            made = ServerChannel(
                len(self._channels) + 1, topic, encoding, schema_name, schema, schema_encoding, keep
            )
            self._channels[made.id] = made
            self._by_topic[topic] = made
        self._call(self._advertise_all, made)
        return made.id

    def log(self, channel_id: int, payload: bytes, log_time_ns: int) -> None:
        """Send one message to its subscribers (and keep it, for a kept channel). Never waits."""
        with self._lock:
            if len(self._inbox) >= MAX_INBOX:
                self.dropped += 1
                return
            self._inbox.append((channel_id, payload, log_time_ns))
            if self._drain_scheduled:
                return
            self._drain_scheduled = True
        self._call(self._drain)

    def _call(self, fn: Callable[..., None], *args: Any) -> None:
        loop = self._loop
        if loop is not None:
            with contextlib.suppress(RuntimeError):  # the loop has ended: nothing to send any more
                loop.call_soon_threadsafe(fn, *args)

    # -- the loop ---------------------------------------------------------------------------------
    def _run(self) -> None:
        try:
            asyncio.run(self._main())
        except BaseException as exc:  # the thread's end must never pass unseen
            if not self._ready.is_set():
                self._error = exc
                self._ready.set()
            else:
                log.exception("the Foxglove server ended")

    async def _main(self) -> None:
        self._loop = asyncio.get_running_loop()
        self._stopping = asyncio.Event()
        try:
            server = await serve(
                self._serve_client,
                self.host,
                self.requested_port,
                process_request=self._handshake,
                subprotocols=list(SUBPROTOCOLS),  # type: ignore[arg-type]
                compression=None,
                max_size=MAX_CLIENT_MESSAGE,
                open_timeout=10,
            )
        except OSError as exc:
            self._error = exc
            self._ready.set()
            return
        self._server = server
        self._port = next(iter(server.sockets)).getsockname()[1]
        self._ready.set()
        await self._stopping.wait()
        server.close()
        with contextlib.suppress(TimeoutError):
            await asyncio.wait_for(server.wait_closed(), 2.0)

    def _handshake(self, connection: ServerConnection, request: Request) -> Response | None:
        refusal = self.gate.check(request.headers.raw_items(), request.path)
        if refusal is None and len(self._clients) >= MAX_CLIENTS:
            refusal_text = f"this bridge serves at most {MAX_CLIENTS} clients at once"
            return self._refuse(connection, 503, refusal_text)
        if refusal is None:
            return None
        return self._refuse(connection, refusal.status, refusal.reason)

    def _refuse(self, connection: ServerConnection, status: int, reason: str) -> Response:
        self.refused += 1
        tell = self.on_refused
        if tell is not None:
            with contextlib.suppress(Exception):
                tell(reason)
        return connection.respond(status, reason + "\n")

    async def _serve_client(self, ws: ServerConnection) -> None:
        client = _Client(self._next_client, ws)
        self._next_client += 1
        self._clients[client.id] = client
        sender = asyncio.get_running_loop().create_task(self._send_loop(client))
        try:
            self._send_info(client)
            adverts = [c.advertisement() for c in self._channels.values()]
            if adverts:
                client.push(json.dumps({"op": "advertise", "channels": adverts}), False)
            async for message in ws:
                if isinstance(message, str):
                    self._on_text(client, message)
                else:
                    self._on_binary(client, message)
        except ConnectionClosed:
            pass
        finally:
            del self._clients[client.id]
            sender.cancel()
            if self.listener is not None and client.publishing:
                self.listener.gone(client.id)

    async def _send_loop(self, client: _Client) -> None:
        with contextlib.suppress(ConnectionClosed):
            while True:
                await client.wake.wait()
                client.wake.clear()
                while client.out:
                    frame, _ = client.out.popleft()
                    client.out_bytes -= len(frame)
                    await client.ws.send(frame)

    def _send_info(self, client: _Client) -> None:
        info: dict[str, Any] = {
            "op": "serverInfo",
            "name": self.name,
            "capabilities": ["clientPublish"] if self.listener is not None else [],
            "metadata": {},
            "sessionId": self._session,
        }
        if self.listener is not None:
            info["supportedEncodings"] = ["json"]
        client.push(json.dumps(info), False)

    def _tell(self, client: _Client, text: str, level: int = STATUS_WARNING) -> None:
        now = time.monotonic()
        if now - client.told.get(text, float("-inf")) < TELL_EVERY:
            return
        client.told[text] = now
        if len(client.told) > 64:
            client.told = {text: now}
        status = {"op": "status", "level": level, "message": text, "id": "rtmu-bridge"}
        client.push(json.dumps(status), False)

    def _advertise_all(self, channel: ServerChannel) -> None:
        text = json.dumps({"op": "advertise", "channels": [channel.advertisement()]})
        for client in list(self._clients.values()):
            client.push(text, False)

    def _drain(self) -> None:
        with self._lock:
            batch = list(self._inbox)
            self._inbox.clear()
            self._drain_scheduled = False
        for channel_id, payload, log_time in batch:
            channel = self._channels.get(channel_id)
            if channel is None:
                continue
            if channel.keep:
                self._kept[channel_id] = (payload, log_time)
            for client in list(self._clients.values()):
                sub = client.by_channel.get(channel_id)
                if sub is not None:
                    self._send_data(client, sub, payload, log_time)

    def _send_data(self, client: _Client, sub: int, payload: bytes, log_time: int) -> None:
        before = client.dropped
        client.push(_DATA.pack(OP_MESSAGE_DATA, sub, log_time) + payload, True)
        self.dropped += client.dropped - before

    # -- what clients send --------------------------------------------------------------------------
    def _on_text(self, client: _Client, text: str) -> None:
        try:
            message = json.loads(text)
        except (ValueError, RecursionError):
            self._tell(client, "a message that is not JSON was ignored", STATUS_ERROR)
            return
        op = message.get("op") if isinstance(message, dict) else None
        if op == "subscribe":
            self._subscribe(client, message.get("subscriptions"))
        elif op == "unsubscribe":
            for sub in _ints(message.get("subscriptionIds")):
                channel_id = client.subscriptions.pop(sub, None)
                if channel_id is not None:
                    client.by_channel.pop(channel_id, None)
        elif op == "advertise":
            self._client_advertise(client, message.get("channels"))
        elif op == "unadvertise":
            for channel_id in _ints(message.get("channelIds")):
                channel = client.publishing.pop(channel_id, None)
                if channel is not None and self.listener is not None:
                    self.listener.unadvertised(client.id, channel)
        else:
            self._tell(client, f"this bridge does not handle {str(op)[:40]!r} messages", STATUS_ERROR)

    def _subscribe(self, client: _Client, subscriptions: object) -> None:
        if not isinstance(subscriptions, list):
            return
        for item in subscriptions[:MAX_SUBSCRIPTIONS]:
            if not isinstance(item, dict):
                continue
            sub, channel_id = _as_id(item.get("id")), _as_id(item.get("channelId"))
            if sub is None or channel_id is None or channel_id not in self._channels:
                self._tell(client, "a subscription to no channel of this bridge was ignored", STATUS_ERROR)
                continue
            if sub in client.subscriptions or channel_id in client.by_channel:
                self._tell(client, "a repeated subscription was ignored", STATUS_ERROR)
                continue
            if len(client.subscriptions) >= MAX_SUBSCRIPTIONS:
                break
            client.subscriptions[sub] = channel_id
            client.by_channel[channel_id] = sub
            kept = self._kept.get(channel_id)
            if kept is not None:  # the latest of it at once: a parked robot's pose, the map …
                self._send_data(client, sub, kept[0], kept[1])

    def _client_advertise(self, client: _Client, channels: object) -> None:
        if self.listener is None:
            self._tell(client, "this bridge takes no client messages (rtmu bridge without --allow-drive)")
            return
        if not isinstance(channels, list):
            return
        for item in channels:
            if not isinstance(item, dict):
                continue
            cid, topic, encoding = _as_id(item.get("id")), item.get("topic"), item.get("encoding")
            schema_name = item.get("schemaName", "")
            if cid is None or not isinstance(topic, str) or not isinstance(encoding, str):
                continue
            if len(client.publishing) >= MAX_CLIENT_CHANNELS and cid not in client.publishing:
                self._tell(client, f"at most {MAX_CLIENT_CHANNELS} channels per client", STATUS_ERROR)
                return
            channel = ClientChannel(cid, topic[:256], encoding[:64], str(schema_name)[:256])
            client.publishing[cid] = channel
            self.listener.advertised(client.id, channel)

    def _on_binary(self, client: _Client, data: bytes) -> None:
        if len(data) < _CLIENT_DATA.size or data[0] != OP_MESSAGE_DATA:
            self._tell(client, "a binary message this bridge does not handle was ignored", STATUS_ERROR)
            return
        _, channel_id = _CLIENT_DATA.unpack_from(data)
        channel = client.publishing.get(channel_id)
        if channel is None or self.listener is None:
            self._tell(client, "a message on a channel the client never advertised was ignored", STATUS_ERROR)
            return
        refusal = self.listener.message(client.id, channel, data[_CLIENT_DATA.size :])
        if refusal is not None:
            self._tell(client, refusal)


def _as_id(value: object) -> int | None:
    """A protocol id (uint32), or None for anything else (a bool, a float, a string …)."""
    if isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= 0xFFFFFFFF:
        return value
    return None


def _ints(values: object) -> list[int]:
    if not isinstance(values, list):
        return []
    return [v for v in (_as_id(x) for x in values[:MAX_SUBSCRIPTIONS]) if v is not None]

"""The live Foxglove bridge: a session's decoded channels on a guarded Foxglove WebSocket server.

The same channels as a recording's decoded ones (pose, TF, status, sonar, laser, camera, map, link
health, notices, stops), made by the same :class:`~rtmu.recorder.convert.Converter` and encoded with
foxglove-sdk's schemas on a worker thread of its own: the network loop only queues (bounded; what does
not fit is dropped and counted). The server (:mod:`.foxglove_server`) checks every handshake
(:mod:`.foxglove_gate`: Origin, Host, a token where clients may drive, the subprotocol) and keeps the
latest message of every state channel — pose, TF, status, map, sensors, camera — for a client that
subscribes later, so a Foxglove opened on a parked robot shows it at once.

Driving (a ``lease``) is off unless asked for; without it the server does not even advertise the
client-publish capability. With it, ``geometry_msgs/Twist``-shaped JSON on a client channel
(Foxglove's Teleop panel: ``/cmd_vel``) drives through the session's own lease by
:mod:`.bridge_drive`'s rules, one client at a time, and the handshake must carry the bridge's token
(made here when none is given: :attr:`Bridge.url` holds it).
"""

from __future__ import annotations

import base64
import contextlib
import json
import queue
import threading
import time
from collections.abc import Callable
from dataclasses import replace
from typing import Any

from ..base.notices import Notice
from ..client.lease import DriveLease
from ..values.state import StateChange
from . import schemas, topics
from .bridge_drive import (
    LEASE_TTL,
    DriveArbiter,
    DriveLimits,
    TwistDrive,
    is_drive_channel,
    twist_ratios,
)
from .convert import Converter, notice_record
from .foxglove_gate import Gate, new_token
from .foxglove_server import ClientChannel, FoxgloveServer

__all__ = ["DEFAULT_PORT", "LEASE_TTL", "QUEUE_SIZE", "Bridge", "DriveLimits", "TwistDrive", "twist_ratios"]

DEFAULT_PORT = 8765
QUEUE_SIZE = 1024
EVENTS = frozenset({topics.NOTICES, topics.STOPS, topics.INTENTS, topics.LEASE, topics.RECORDER})
"""Topics of things that happened: not sent again to a client that subscribes later. Every other
channel is a state, whose latest message such a client gets at once."""


class _Clients:
    """The bridge's side of clients that publish: drive channels → the arbiter (server thread)."""

    def __init__(self, arbiter: DriveArbiter) -> None:
        self.arbiter = arbiter
        self.drive_channels: set[tuple[int, int]] = set()

    def advertised(self, client: int, channel: ClientChannel) -> None:
        if is_drive_channel(channel.topic, channel.encoding, channel.schema_name):
            self.drive_channels.add((client, channel.id))

    def unadvertised(self, client: int, channel: ClientChannel) -> None:
        if (client, channel.id) in self.drive_channels:
            self.drive_channels.discard((client, channel.id))
            self.arbiter.release(client)

    def message(self, client: int, channel: ClientChannel, data: bytes) -> str | None:
        if (client, channel.id) not in self.drive_channels:
            topic = channel.topic[:60]
            return f"this bridge takes only drive messages (JSON Twist on /cmd_vel), not {topic!r}"
        return self.arbiter.message(client, data)

    def gone(self, client: int) -> None:
        self.drive_channels = {c for c in self.drive_channels if c[0] != client}
        self.arbiter.release(client)


class Bridge:
    """``Bridge(port=…, lease=runner.lease if drive)``; tap a runner: ``on_publish=bridge.published``."""

    def __init__(
        self,
        *,
        host: str = "127.0.0.1",
        port: int = DEFAULT_PORT,
        lease: DriveLease | None = None,
        limits: DriveLimits | None = None,
        gate: Gate | None = None,
        name: str = "rtmu",
    ) -> None:
        self.host = host
        self.requested_port = port
        self.name = name
        self.drive = TwistDrive(lease, limits or DriveLimits()) if lease is not None else None
        """None: no driving at all (and no client-publish capability advertised)."""
        self.arbiter = DriveArbiter(self.drive) if self.drive is not None else None
        gate = gate or Gate()
        if self.drive is not None and gate.token is None:
            gate = replace(gate, token=new_token())  # a bridge that drives never goes without one
        self.gate = gate
        self.server = FoxgloveServer(
            host=host,
            port=port,
            gate=gate,
            name=name,
            listener=_Clients(self.arbiter) if self.arbiter is not None else None,
        )
        self.dropped = 0
        self.published_messages = 0
        self._queue: queue.Queue[tuple[str, Any, int] | None] = queue.Queue(QUEUE_SIZE)
        self._converter = Converter()
        self._channels: dict[str, tuple[int, Callable[[Any], bytes]]] = {}
        self._worker = threading.Thread(target=self._work, name="rtmu-bridge", daemon=True)
        self.on_logged: Callable[[str, int], None] | None = None
        """Optional tap (tests, bench): ``(topic, log_time_ns)`` after each message went to the server."""

    @property
    def port(self) -> int:
        return self.server.port

    @property
    def url(self) -> str:
        """What a Foxglove client opens: ``ws://HOST:PORT`` (with ``/?token=…`` where clients may drive)."""
        host = self.host if ":" not in self.host else f"[{self.host}]"
        token = f"/?token={self.gate.token}" if self.gate.token else ""
        return f"ws://{host}:{self.port}{token}"

    def start(self) -> Bridge:
        self.server.start()
        self._worker.start()
        return self

    def close(self) -> None:
        """Stop driving, then the worker and the server."""
        if self.drive is not None:
            self.drive.stop()
        self._put(None, force=True)
        if self._worker.is_alive():
            self._worker.join(2.0)
        self.server.close()

    # -- producers (network thread, server thread) --------------------------------------------
    def published(self, change: StateChange) -> None:
        self._put(("change", change, time.time_ns()))

    def notice(self, notice: Notice) -> None:
        self._put(("event", (topics.NOTICES, notice_record(notice)), time.time_ns()))

    def stopped(self, reason: str, sent: bool = True) -> None:
        record = {"by": "client", "reason": reason, "sent": sent}
        self._put(("event", (topics.STOPS, record), time.time_ns()))

    def _put(self, item: tuple[str, Any, int] | None, force: bool = False) -> None:
        try:
            self._queue.put_nowait(item)
        except queue.Full:
            if force:  # the end: wait a little for room, then leave the worker to the daemon thread's fate
                with contextlib.suppress(queue.Full):
                    self._queue.put(item, timeout=1.0)
            else:
                self.dropped += 1

    # -- the worker ------------------------------------------------------------------------------
    def _work(self) -> None:
        while True:
            item = self._queue.get()
            if item is None:
                return
            kind, value, at_ns = item
            try:
                if kind == "change":
                    for topic, message in self._converter.change(value, at_ns):
                        self._log(topic, message, at_ns)
                elif kind == "event":
                    self._log(value[0], value[1], at_ns)
            except Exception:  # one bad value never ends the bridge
                self.dropped += 1

    def _log(self, topic: str, message: Any, at_ns: int) -> None:
        known = self._channels.get(topic)
        if known is None:
            known = self._channels[topic] = self._channel(topic, message)
        channel_id, encode = known
        self.server.log(channel_id, encode(message), at_ns)
        self.published_messages += 1
        tap = self.on_logged
        if tap is not None:
            tap(topic, at_ns)

    def _channel(self, topic: str, message: Any) -> tuple[int, Callable[[Any], bytes]]:
        """``topic``'s server channel: a foxglove-sdk schema (protobuf), or JSON with its named schema."""
        keep = topic not in EVENTS
        if isinstance(message, dict):
            schema = schemas.schema_data(topic).decode()
            channel_id = self.server.channel(
                topic,
                encoding="json",
                schema_name=schemas.schema_name(topic),
                schema=schema,
                schema_encoding=schemas.ENCODING,
                keep=keep,
            )
            return channel_id, _json_bytes
        described = type(message).get_schema()
        channel_id = self.server.channel(
            topic,
            encoding=described.encoding,
            schema_name=described.name,
            schema=base64.b64encode(described.data).decode(),
            schema_encoding=described.encoding,
            keep=keep,
        )
        return channel_id, _encoded


def _json_bytes(message: Any) -> bytes:
    return json.dumps(message, separators=(",", ":")).encode()


def _encoded(message: Any) -> bytes:
    return bytes(message.encode())

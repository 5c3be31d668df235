"""A minimal Foxglove WebSocket protocol client over the ``websockets`` package.

Written from the protocol's published spec, independent of foxglove-sdk's server: JSON
``serverInfo`` / ``advertise`` / ``subscribe`` / client ``advertise``, binary message data
(opcode 1: subscription id u32, log time u64, payload) and client message data (opcode 1:
channel id u32, payload).
"""

from __future__ import annotations

import json
import struct
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from websockets.sync.client import ClientConnection, connect

SUBPROTOCOL = "foxglove.sdk.v1"
"""What foxglove-sdk 0.30 asks for (the successor of ``foxglove.websocket.v1``, same messages)."""
OLD_SUBPROTOCOL = "foxglove.websocket.v1"
"""What the protocol's spec, older Foxglove and other ws-protocol clients ask for."""


@dataclass
class Received:
    topic: str
    log_time: int
    data: bytes
    at: float
    """time.monotonic() when it arrived."""


@dataclass
class FoxgloveClient:
    url: str
    ws: ClientConnection | None = None
    server_info: dict[str, Any] = field(default_factory=dict)
    channels: dict[str, dict[str, Any]] = field(default_factory=dict)
    """Topic → the advertised channel."""
    messages: list[Received] = field(default_factory=list)
    statuses: list[dict[str, Any]] = field(default_factory=list)
    """Every ``status`` message the server sent this client."""
    subprotocol: str = SUBPROTOCOL
    origin: str | None = None
    """The Origin header a browser page would send (None: none, as a non-browser client)."""
    _subs: dict[int, str] = field(default_factory=dict)

    def __enter__(self) -> FoxgloveClient:
        opened = connect(
            self.url,
            subprotocols=[self.subprotocol],  # type: ignore[list-item]
            origin=self.origin,  # type: ignore[arg-type]
            open_timeout=5,
        )
        self.ws = opened.__enter__()
        return self

    def __exit__(self, *exc: object) -> None:
        assert self.ws is not None
        self.ws.__exit__(None, None, None)

    def pump(self, seconds: float) -> None:
        """Read whatever arrives for ``seconds``."""
        self.until(lambda: False, seconds, must=False)

    def until(self, condition: Callable[[], bool], timeout: float = 10.0, *, must: bool = True) -> None:
        assert self.ws is not None
        end = time.monotonic() + timeout
        while not condition():
            left = end - time.monotonic()
            if left <= 0:
                assert not must, "timed out waiting on the Foxglove server"
                return
            try:
                frame = self.ws.recv(timeout=min(left, 0.1))
            except TimeoutError:
                continue
            self._handle(frame)

    def _handle(self, frame: str | bytes) -> None:
        if isinstance(frame, str):
            message = json.loads(frame)
            op = message.get("op")
            if op == "serverInfo":
                self.server_info = message
            elif op == "advertise":
                for channel in message["channels"]:
                    self.channels[channel["topic"]] = channel
            elif op == "status":
                self.statuses.append(message)
            return
        if frame[0] == 1:
            sub, log_time = struct.unpack_from("<IQ", frame, 1)
            self.messages.append(Received(self._subs.get(sub, "?"), log_time, frame[13:], time.monotonic()))

    def subscribe(self, *topics: str) -> None:
        assert self.ws is not None
        self.until(lambda: all(t in self.channels for t in topics), 10)
        subs = []
        for topic in topics:
            sub = len(self._subs) + 1
            self._subs[sub] = topic
            subs.append({"id": sub, "channelId": self.channels[topic]["id"]})
        self.ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))

    def advertise(self, channel_id: int, topic: str, schema_name: str = "geometry_msgs/Twist") -> None:
        assert self.ws is not None
        channel = {"id": channel_id, "topic": topic, "encoding": "json", "schemaName": schema_name}
        self.ws.send(json.dumps({"op": "advertise", "channels": [channel]}))

    def publish(self, channel_id: int, payload: bytes) -> None:
        assert self.ws is not None
        self.ws.send(struct.pack("<BI", 1, channel_id) + payload)

    def of(self, topic: str) -> list[Received]:
        return [m for m in self.messages if m.topic == topic]


def twist(linear: float, angular: float = 0.0) -> bytes:
    return json.dumps(
        {"linear": {"x": linear, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": angular}}
    ).encode()

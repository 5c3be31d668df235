"""The live Foxglove bridge: a session's decoded channels on a Foxglove WebSocket server (foxglove-sdk).

The same channels as a recording's decoded ones (pose, TF, status, sonar, laser, camera,
map, link health, notices, stops), made by the same :class:`~rtmu.recorder.convert.Converter`
on a worker thread of its own: the network loop only queues (bounded; what does not fit is
dropped and counted). The map, status and connection are kept and sent again to a client
that subscribes later, so a Foxglove opened after the map loaded still shows it.

Driving (``allow_drive``) is off unless asked for; without it the server does not even
advertise the client-publish capability. With it, ``geometry_msgs/Twist``-shaped JSON on
a client channel (Foxglove's Teleop panel: ``/cmd_vel``) drives through the session's own
:class:`~rtmu.client.lease.DriveLease` — :class:`TwistDrive` holds the rules: motion only
while messages keep coming at 5 Hz or more, the lease (220 ms) lapses and the session stops
the robot when they cease, and a lease ended by anything else (a stale link, a stop) needs
a pause in the stream before the same stream can drive again.
"""

from __future__ import annotations

import contextlib
import json
import math
import queue
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import foxglove
from foxglove import Channel, Context
from foxglove.websocket import Capability, ChannelView, Client, ClientChannel, WebSocketServer

from ..base.notices import Notice
from ..client.lease import DriveLease, DriveRatios, EndReason
from ..values.state import StateChange
from . import topics
from .convert import Converter, notice_record
from .mcapfile import TYPED

DEFAULT_PORT = topics.BRIDGE_PORT
QUEUE_SIZE = 1024
MAX_GAP = 0.2
"""Seconds between drive messages above which the stream no longer drives (5 Hz)."""
LEASE_TTL = 0.22
"""The drive lease of a bridge's session (``ClientRunner(lease_ttl=…)``): a stream that ends stops
the robot this long after its last message — under 300 ms with the stop's way to the robot."""
MIN_INTERVAL = 0.02
"""Drive messages closer than this (over 50 Hz) only keep the drive alive: a flood cannot make the
session send ``ratioDrive`` faster than that."""
MAX_DRIVE_MESSAGE = 4096
DRIVE_TOPICS = frozenset({"/cmd_vel"})
TWIST_SCHEMAS = frozenset({"geometry_msgs/Twist", "geometry_msgs/msg/Twist"})
KEPT = frozenset({topics.MAP, topics.MAP_POINTS, topics.MAP_STATE, topics.STATUS, topics.CONNECTION})
"""Topics whose last message a newly subscribed client gets at once."""


@dataclass(frozen=True, slots=True)
class DriveLimits:
    max_linear: float = 1.0
    """m/s in a Twist that means full forward ratio (Foxglove's Teleop sends 1.0 by default)."""
    max_angular: float = 1.0
    """rad/s that means a full turn ratio."""
    throttle: float = 50.0
    """The throttle every bridge drive uses, %."""


def twist_ratios(data: bytes, limits: DriveLimits) -> DriveRatios | None:
    """A Twist-shaped JSON message → drive ratios; None when it is not one (too big, not JSON, no numbers)."""
    if len(data) > MAX_DRIVE_MESSAGE:
        return None
    try:
        message = json.loads(data)
        linear = float(message.get("linear", {}).get("x", 0.0))
        angular = float(message.get("angular", {}).get("z", 0.0))
    except (ValueError, TypeError, AttributeError, UnicodeDecodeError, RecursionError):
        return None
    if not (math.isfinite(linear) and math.isfinite(angular)):
        return None

    def pct(value: float, full: float) -> float:
        return max(-100.0, min(100.0, value / full * 100.0))

    return DriveRatios(pct(linear, limits.max_linear), pct(angular, limits.max_angular), limits.throttle)


class TwistDrive:
    """Drive messages → the session's drive lease, by the bridge's rules. Thread-safe."""

    def __init__(self, lease: DriveLease, limits: DriveLimits, clock: Callable[[], float] = time.monotonic):
        self.lease = lease
        self.limits = limits
        self.clock = clock
        self.received = 0
        self.rejected = 0
        """Messages that were no Twist (ignored: they neither drive nor keep a drive alive)."""
        self._lock = threading.Lock()
        self._last = float("-inf")
        self._generation: int | None = None
        self._blocked = False
        """Our lease was ended by something else: the stream must pause before it drives again."""

    def message(self, data: bytes) -> None:
        ratios = twist_ratios(data, self.limits)
        with self._lock:
            if ratios is None:
                self.rejected += 1
                return
            self.received += 1
            now = self.clock()
            gap, self._last = now - self._last, now
            if gap > MAX_GAP or not ratios.moving:
                self._blocked = False  # a pause (or a zero Twist) is the stream's "key released"
            if not ratios.moving:
                self._end(EndReason.RELEASED)
                return
            if self._generation is not None:
                same = ratios == self.lease.view(now).ratios
                if gap <= MAX_GAP and (
                    self.lease.renew() if same or gap < MIN_INTERVAL else self.lease.change(ratios)
                ):
                    return
                if self.lease.ended not in (None, EndReason.LAPSED):
                    self._blocked = True  # a stop or the link ended it, not the stream
                self._end(EndReason.LAPSED)
            if gap <= MAX_GAP and not self._blocked:  # two messages within 200 ms: the stream drives
                self._generation = self.lease.grant(ratios)

    def stop(self) -> None:
        """The publishing client went away or unadvertised: stop at once."""
        with self._lock:
            self._end(EndReason.RELEASED)
            self._last = float("-inf")

    def _end(self, reason: EndReason) -> None:
        if self._generation is not None:
            self.lease.end(reason, self._generation)
            self._generation = None


class _Listener:
    """foxglove-sdk's server callbacks (on its own thread): drive channels and late subscribers."""

    def __init__(self, bridge: Bridge) -> None:
        self.bridge = bridge
        self.drive_channels: set[tuple[int, int]] = set()

    def on_subscribe(self, client: Client, channel: ChannelView) -> None:
        if channel.topic in KEPT:
            self.bridge.resend(channel.topic)

    def on_unsubscribe(self, client: Client, channel: ChannelView) -> None:
        return None

    def on_client_advertise(self, client: Client, channel: ClientChannel) -> None:
        drive = self.bridge.drive
        if drive is None or channel.encoding != "json":
            return
        if channel.topic in DRIVE_TOPICS or channel.schema_name in TWIST_SCHEMAS:
            self.drive_channels.add((client.id, channel.id))

    def on_client_unadvertise(self, client: Client, client_channel_id: int) -> None:
        if (client.id, client_channel_id) in self.drive_channels:
            self.drive_channels.discard((client.id, client_channel_id))
            if self.bridge.drive is not None:
                self.bridge.drive.stop()

    def on_message_data(self, client: Client, client_channel_id: int, data: bytes) -> None:
        drive = self.bridge.drive
        if drive is not None and (client.id, client_channel_id) in self.drive_channels:
            drive.message(bytes(data))


class Bridge:
    """``Bridge(port=…, lease=runner.lease if drive)``; tap a runner: ``on_publish=bridge.published``."""

    def __init__(
        self,
        *,
        host: str = "127.0.0.1",
        port: int = DEFAULT_PORT,
        lease: DriveLease | None = None,
        limits: DriveLimits | None = None,
        name: str = "rtmu",
    ) -> None:
        self.host = host
        self.requested_port = port
        self.name = name
        self.drive = TwistDrive(lease, limits or DriveLimits()) if lease is not None else None
        """None: no driving at all (and no client-publish capability advertised)."""
        self.context = Context()
        self.server: WebSocketServer | None = None
        self.dropped = 0
        self.published_messages = 0
        self._queue: queue.Queue[tuple[str, Any, int] | None] = queue.Queue(QUEUE_SIZE)
        self._converter = Converter()
        self._channels: dict[str, Any] = {}
        self._kept: dict[str, tuple[Any, int]] = {}
        self._worker = threading.Thread(target=self._work, name="rtmu-bridge", daemon=True)
        self.on_logged: Callable[[str, int], None] | None = None
        """Optional tap (tests, bench): ``(topic, log_time_ns)`` after each message went to the server."""

    @property
    def port(self) -> int:
        assert self.server is not None, "start() first"
        return int(self.server.port)

    def start(self) -> Bridge:
        capabilities = [Capability.ClientPublish] if self.drive is not None else []
        self.server = foxglove.start_server(
            name=self.name,
            host=self.host,
            port=self.requested_port,
            capabilities=capabilities,
            server_listener=_Listener(self),  # type: ignore[arg-type]
            supported_encodings=["json"] if self.drive is not None else None,
            context=self.context,
        )
        self._worker.start()
        return self

    def close(self) -> None:
        """Stop driving, then the worker and the server."""
        if self.drive is not None:
            self.drive.stop()
        self._put(None, force=True)
        if self._worker.is_alive():
            self._worker.join(2.0)
        if self.server is not None:
            self.server.stop()
            self.server = None

    # -- producers (network thread, server thread) --------------------------------------------
    def published(self, change: StateChange) -> None:
        self._put(("change", change, time.time_ns()))

    def notice(self, notice: Notice) -> None:
        self._put(("event", (topics.NOTICES, notice_record(notice)), time.time_ns()))

    def stopped(self, reason: str, sent: bool = True) -> None:
        record = {"by": "client", "reason": reason, "sent": sent}
        self._put(("event", (topics.STOPS, record), time.time_ns()))

    def resend(self, topic: str) -> None:
        self._put(("resend", topic, time.time_ns()))

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
                elif kind == "resend" and value in self._kept:
                    message, _ = self._kept[value]
                    self._log(value, message, at_ns)
            except Exception:  # one bad value never ends the bridge
                self.dropped += 1

    def _log(self, topic: str, message: Any, at_ns: int) -> None:
        channel = self._channels.get(topic)
        if channel is None:
            kind = TYPED.get(topic)
            channel = kind(topic, context=self.context) if kind else Channel(topic, context=self.context)
            self._channels[topic] = channel
        if topic in KEPT:
            self._kept[topic] = (message, at_ns)
        channel.log(message, log_time=at_ns)
        self.published_messages += 1
        tap = self.on_logged
        if tap is not None:
            tap(topic, at_ns)

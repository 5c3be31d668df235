"""One operator session on the network loop: connection, subscriptions, map, drive, health, reconnect.

The :class:`Session` lives entirely on the network thread's asyncio loop (see
``runner`` for the thread and the UI-facing facade). It keeps a *shadow* of
every part of the robot's state (robot, map, camera, connection, health) and
hands a typed change (:data:`rtmu.state.StateChange`) to ``publish`` only when
the value really changed, so an unchanged 10 Hz status costs the UI thread
nothing. Messages for the operator leave as typed :class:`rtmu.notices.Notice`.

Its heart is one task that wakes at the exact moments something is due — a
``ratioDrive`` resend, the lease's expiry, the status going stale — or when the
UI changes the lease, and then asks the pure :class:`DriveGovernor` and
:class:`HealthMonitor` what to do. Because it never waits for the UI thread,
a long redraw cannot delay a packet; because motion needs a lease the UI keeps
renewing, a frozen UI cannot keep the robot moving.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Any

from ..guardian.handle import BEAT_PERIOD, GuardianHandle
from ..guardian.messages import Hello
from ..notices import Kind, Notice
from ..protocol.client_connection import payload_name
from ..protocol.errors import ProtocolError
from ..protocol.payloads import Payload, Side, decode_payload, payload_type_for
from ..protocol.payloads.drive import RatioDrive, SafeDrive, SetSafeDrive
from ..protocol.payloads.navigation import Dock, GotoGoal, GotoPose, Home, LocalizeToPose, TourGoals
from ..protocol.payloads.robot import BatteryInfo, ModeInfo, Update, UpdateNumbers, UpdateStrings
from ..state import (
    CameraChanged,
    CameraImage,
    ConnectionChanged,
    ConnectionState,
    HealthChanged,
    LinkHealth,
    LinkLevel,
    MapChanged,
    MapModel,
    MapPhase,
    Phase,
    RobotChanged,
    RobotState,
    StateChange,
)
from .config_feed import ConfigFeed, ServerConfig, fetch_config, set_config
from .connection import AriaClient, Packet
from .custom_commands import CommandCatalogue, ServerCommand, list_commands, run_command
from .diagnosis import explain
from .drawings_feed import DrawingsFeed
from .errors import ClientError, ClientTimeout, MalformedReply, NotSupported, ProtocolFault, ServerClosed
from .health import HealthMonitor, ping_data
from .ld_data import LASER_NAMES
from .ld_session import LdFeed
from .lease import DriveGovernor, DriveLease, EndReason, SendRatios, SendStop
from .mapcache import MapCache, MapKey, SharedMaps, content_key, map_key
from .mapload import download_map, map_source
from .nav_session import NavFeed
from .popups import PopupFeed
from .ptz import PtzFeed
from .reconnect import Backoff, worth_retrying
from .server_strings import StringsFeed
from .subscriptions import Subscription, applicable
from .video_feed import frame_stamp
from .video_session import LiveVideo

log = logging.getLogger(__name__)

Publish = Callable[[StateChange], None]
"""``publish(change)``: a new whole value for one part of the robot's state."""
NoticeFn = Callable[[Notice], None]
"""``notice(notice)``: a message for the operator, typed by what it is about."""
ClientFactory = Callable[[Callable[[ClientError], None]], AriaClient]
"""``factory(on_close)`` → a fresh, unconnected :class:`AriaClient` (its link is the factory's choice)."""

HEART_MAX_SLEEP = 0.25
STEP_TIMEOUT = 2.0
"""``step()`` gives up (ClientTimeout) if the heart has not run within this many seconds."""
TASK_END_TIMEOUT = 0.5
"""How long closing waits for a cancelled task to finish before leaving it behind."""


@dataclass
class SessionConfig:
    status_interval_ms: int = 100
    """``updateNumbers`` period: the status stream is also the link's heartbeat."""
    sonar_interval_ms: int = 200
    wifi_interval_ms: int = 1000
    """``getStrings`` period (Wi-Fi gauges, and the details table while it is open)."""
    loc_state_interval_ms: int = 1000
    """``getLocState`` period, where the server offers it."""
    path_interval_ms: int = 500
    """``getPath`` period, only while the server navigates."""
    ping_interval: float = 1.0
    connect_timeout: float = 10.0
    reply_timeout: float = 5.0
    lost_after: float = 2.0
    ping_timeout: float | None = None
    """The longest a ping may go unanswered (None: ``health.PING_CEILING``; learned below it)."""
    fetch_map: bool = True
    backoff: Callable[[], Backoff] = field(default=Backoff)
    guardian: bool = False
    """Start a guardian process (:mod:`rtmu.guardian`) for each connection that may drive: it stops
    the robot if this process is killed or frozen while driving. The window and ``rtmu drive`` do."""
    shared_maps: SharedMaps | None = field(default=None, compare=False)
    """Maps shared with the process's other sessions (a fleet's window: one download per map file)."""


@dataclass
class _Target:
    host: str
    port: int
    user: str
    password: str
    profile: str
    auto_reconnect: bool
    protocol: str | None = None
    """None: answer with the protocol string the server advertises."""


class Session:
    """See the module notes. Create on the loop; every method runs on the loop's thread."""

    def __init__(
        self,
        lease: DriveLease,
        publish: Publish,
        notice: NoticeFn | None = None,
        *,
        clock: Callable[[], float] = time.monotonic,
        config: SessionConfig | None = None,
        client_factory: ClientFactory | None = None,
        subscriptions: tuple[SessionSubscription, ...] | None = None,
    ) -> None:
        self.lease = lease
        self.publish_fn = publish
        self.notice_fn: NoticeFn = notice or (lambda notice: None)
        self.clock = clock
        self.config = config or SessionConfig()
        self.client_factory: ClientFactory = client_factory or (
            lambda on_close: AriaClient(on_close=on_close, clock=self.clock)
        )
        """Makes each connection's client: a replay or a test passes one over its own link."""
        self.subscriptions = SUBSCRIPTIONS if subscriptions is None else subscriptions
        """What every connection subscribes to (see :data:`SUBSCRIPTIONS`)."""
        self.health = HealthMonitor(
            self.config.status_interval_ms / 1000.0,
            lost_after=self.config.lost_after,
            ping_ceiling=self.config.ping_timeout,
        )
        self.governor = DriveGovernor(lease)
        self.client: AriaClient | None = None
        self._target: _Target | None = None
        self._published: dict[type, StateChange] = {}
        self._robot = RobotState()
        self._map = MapModel()
        self._map_cache = MapCache()
        self.map_downloads_skipped = 0
        """Map loads answered from the cache (same ``getMapId``): what a reconnect saved."""
        self.map_downloads_shared = 0
        """Map loads answered by another session's download of the same map (``config.shared_maps``)."""
        self._connection = ConnectionState()
        self._extra_subs: dict[str, tuple[int, Callable[[Packet], None]]] = {}
        self._tasks: set[asyncio.Task[Any]] = set()
        self._reconnect_task: asyncio.Task[None] | None = None
        self._connecting: asyncio.Task[Any] | None = None
        self._heart_task: asyncio.Task[None] | None = None
        self._map_task: asyncio.Task[MapModel] | None = None
        self._map_dirty = False
        """The map changed (or was asked for) while a download was in flight: fetch once more."""
        self._kick = asyncio.Event()
        self._stepped: asyncio.Event = asyncio.Event()
        self._image_sequence = 0
        self.packets_sent = 0
        self.on_stop: Callable[[str, bool], None] | None = None
        """Optional tap (a flight recorder): ``on_stop(reason, sent)`` after every zero-ratios + ``stop``."""
        self.guardian: GuardianHandle | None = None
        self._stop_on_connect = False
        """The link was lost while driving: reconnect at once and send a stop first."""
        self.ld = LdFeed(self._robot_update, self._decode, self._spawn, self.config.reply_timeout)
        """LD (ARAM) data: lasers, docking state, routes, DataStore_* — only where listed."""
        self.nav = NavFeed(
            self._publish, self._notice, self._decode, self._spawn, self.config.reply_timeout, self._goal_pose
        )
        """Navigation (ARNL): goals, path, outcome, localization — read from what the server lists."""
        self.nav.changed = self._sync_subscriptions
        self.popups = PopupFeed(
            self._publish, self._notice, self._decode, self._spawn, self.config.reply_timeout
        )
        """Server popups (§4.9): the open set as PopupsChanged, closing words as Kind.SERVER notices."""
        self.strings = StringsFeed(self._robot_update, self._decode, self._spawn, self.config.reply_timeout)
        """Server strings (§4.11): Wi-Fi gauges, and the details table while it is open."""
        self.strings.interval_ms = self.config.wifi_interval_ms
        self.ptz = PtzFeed(self._robot_update, self._spawn, self.config.reply_timeout)
        """The pan-tilt-zoom camera head (§4.6): limits, position while watched, moves."""
        self.config_feed = ConfigFeed()
        """``configUpdated`` broadcasts (the configuration page refreshes on them)."""
        self.video = LiveVideo(self._publish, self._spawn, self.clock)
        """Live video (``client.video_session``): frames go out as the camera part; resumes on reconnect."""
        self._held_subs: set[str] = set()
        """Conditional subscriptions (``only_while``) held now on this connection."""
        also = {"sonarCurrent": self._on_sonar, **dict.fromkeys(LASER_NAMES, self.ld.on_laser)}
        self.drawings = DrawingsFeed(self._publish, self._spawn, self.config.reply_timeout, also)
        """The server's drawings (getDrawingList): each shown one asked for at its own period."""

    # -- publishing --------------------------------------------------------------------------
    def _publish(self, change: StateChange) -> None:
        part = type(change)
        if self._published.get(part) == change:
            return
        self._published[part] = change
        try:
            self.publish_fn(change)
        except Exception:
            log.exception("publishing %s failed", part.__name__)

    def _robot_update(self, **changes: Any) -> None:
        self._robot = replace(self._robot, **changes)
        self._publish(RobotChanged(self._robot))
        self.nav.robot(self._robot)

    def _set_connection(self, **changes: Any) -> None:
        self._connection = replace(self._connection, **changes)
        self._publish(ConnectionChanged(self._connection))

    def _set_map(self, value: MapModel) -> None:
        self._map = value
        self._publish(MapChanged(value))

    def _notice(self, notice: Notice) -> None:
        try:
            self.notice_fn(notice)
        except Exception:
            log.exception("notice callback failed")

    # -- connect / disconnect ----------------------------------------------------------------
    @property
    def connected(self) -> bool:
        return self.client is not None and self.client.connected

    async def connect(
        self,
        host: str,
        port: int,
        user: str = "",
        password: str = "",
        *,
        profile: str = "",
        auto_reconnect: bool = True,
        protocol: str | None = None,
    ) -> None:
        """Connect and set up the session; raises the :class:`ClientError` after publishing FAILED.

        A :meth:`disconnect` (or another ``connect``) while this one is still logging in cancels it.
        """
        self._cancel_connecting()
        self._connecting = asyncio.current_task()
        if self.connected:  # connecting again (another profile) while driving: stop on the old link first
            self._send_stop("connecting elsewhere")
        self.lease.end(EndReason.DISCONNECTED)
        await self._drop_client()
        self._cancel_reconnect()
        self._stop_on_connect = False  # that was another connection's robot
        target = self._target = _Target(host, port, user, password, profile, auto_reconnect, protocol)
        self._robot = RobotState()
        self._publish(RobotChanged(self._robot))
        self.nav.disconnected()
        self.popups.disconnected()
        self.strings.disconnected()
        self.ptz.disconnected()
        self.video.disconnected()
        self.video.stop()  # a new connection (or none) starts without video: the operator asks again
        self.drawings.disconnected()
        self._set_map(MapModel())
        self._publish(CameraChanged(None))
        self._set_connection(
            phase=Phase.CONNECTING, host=host, port=port, user=user, profile=profile,
            offers=frozenset(), error="", error_kind="", attempt=0, retry_in=None,
        )  # fmt: skip
        self._ensure_heart()
        try:
            await self._open(target)
        except ClientError as exc:
            if self._target is target:
                # The same words as ``rtmu doctor``: what failed, then what to do next.
                self._set_connection(phase=Phase.FAILED, error=explain(exc).sentence(), error_kind=exc.kind)
            raise
        finally:
            if self._connecting is asyncio.current_task():
                self._connecting = None

    def _cancel_connecting(self) -> None:
        task, self._connecting = self._connecting, None
        if task is not None and task is not asyncio.current_task() and not task.done():
            task.cancel()

    async def _open(self, target: _Target) -> None:
        client = self.client_factory(lambda error: self._on_client_closed(client, error))
        await client.connect(
            target.host,
            target.port,
            target.user,
            target.password,
            timeout=self.config.connect_timeout,
            protocol=target.protocol,
        )
        if self._target is not target:  # disconnected (or re-targeted) meanwhile
            await client.disconnect()
            raise ServerClosed("the connection attempt was cancelled")
        self.client = client
        if self._stop_on_connect:  # the link was lost while driving: the robot may still be moving
            self._stop_on_connect = False
            self._send_stop("reconnected after the link was lost while driving")
        if self.config.guardian and client.supports("ratioDrive"):
            self._start_guardian(target)
        # Whatever happened before, the robot stays still until a fresh key press.
        self.lease.end(EndReason.DISCONNECTED)
        self.governor.reset()
        self.health.start(self.clock())
        self.health.bind(f"{target.host}:{target.port}", lambda: client.last_packet_at, client.undecided)
        offers = frozenset(e.name for e in client.datalist)
        self.nav.connected(client)
        self._setup_subscriptions(client)
        self.popups.connected(client)  # after the popupCreate subscription: popupList's answers go there
        self.video.connected(client)
        self.drawings.connected(client)  # after the sonar subscription, which a shown drawing replaces
        self._set_connection(phase=Phase.CONNECTED, offers=offers, error="", error_kind="", retry_in=None)
        self._spawn(self._ping_loop(client), "ping")
        self._spawn(self.ptz.connected(client), "ptz")  # first: a server without cameras is known at once
        self._spawn(self._fetch_once_infos(client), "infos")
        if self.config.fetch_map:
            self._request_map()
        self.kick()

    async def disconnect(self) -> None:
        """Stop the robot, say goodbye, forget the robot's values. Returns within a fraction of a second."""
        self._cancel_connecting()
        self._cancel_reconnect()
        self._target = None
        if self.connected:
            self._send_stop("disconnect")
        self.lease.end(EndReason.DISCONNECTED)
        await self._drop_client()
        self._robot = RobotState()
        self._publish(RobotChanged(self._robot))
        self.nav.disconnected()
        self.popups.disconnected()
        self.strings.disconnected()
        self.ptz.disconnected()
        self.video.disconnected()
        self.video.stop()  # a new connection (or none) starts without video: the operator asks again
        self.drawings.disconnected()
        self._set_map(MapModel())
        self._publish(CameraChanged(None))
        self._set_connection(
            phase=Phase.DISCONNECTED, offers=frozenset(), error="", error_kind="", retry_in=None
        )
        self._publish_health()

    async def close(self) -> None:
        """Disconnect and end every task (runner shutdown); each wait is bounded."""
        await self.disconnect()
        task, self._heart_task = self._heart_task, None
        if task is not None:
            task.cancel()
            await asyncio.wait({task}, timeout=TASK_END_TIMEOUT)

    async def _drop_client(self) -> None:
        client, self.client = self.client, None
        self._close_guardian(goodbye=True)
        for task in list(self._tasks):
            task.cancel()
        self.health.stop()
        self.governor.reset()
        if client is not None:
            await client.disconnect()

    def _on_client_closed(self, client: AriaClient, error: ClientError) -> None:
        if client is not self.client:
            return
        self._connection_lost(error)

    def _connection_lost(self, error: ClientError) -> None:
        """Not our choice: the server died, closed, or the link was lost."""
        client, self.client = self.client, None
        self.video.disconnected()
        # Our link died while driving: we cannot stop the robot, the guardian (its own link) can —
        # and our first reconnect, at once, begins with a stop (the guardian's link may be gone too).
        self._stop_on_connect = self.governor.driving
        self._close_guardian(goodbye=not self.governor.driving)
        for task in list(self._tasks):
            task.cancel()
        if client is not None:
            self._spawn_detached(client.disconnect())
        self.lease.end(EndReason.DISCONNECTED)
        self.governor.reset()
        self.health.stop()
        self._publish_health()
        target = self._target
        if target is not None and target.auto_reconnect and worth_retrying(error):
            self._set_connection(phase=Phase.RECONNECTING, error=str(error), error_kind=error.kind, attempt=0)
            self._reconnect_task = asyncio.get_running_loop().create_task(self._reconnect(target))
        else:
            self._set_connection(phase=Phase.FAILED, error=str(error), error_kind=error.kind, retry_in=None)

    async def _reconnect(self, target: _Target) -> None:
        backoff = self.config.backoff()
        at_once = self._stop_on_connect  # lost while driving: the first try carries a stop, no wait
        while self._target is target:
            delay = 0.0 if at_once else backoff.next_delay()
            at_once = False
            self._set_connection(phase=Phase.RECONNECTING, attempt=backoff.attempt, retry_in=round(delay, 1))
            await asyncio.sleep(delay)
            if self._target is not target:
                return
            try:
                await self._open(target)
            except ClientError as exc:
                if not worth_retrying(exc):
                    self._set_connection(
                        phase=Phase.FAILED, error=str(exc), error_kind=exc.kind, retry_in=None
                    )
                    return
                self._set_connection(error=str(exc), error_kind=exc.kind)
                continue
            self._notice(
                Notice.info(
                    Kind.LINK, f"Reconnected to {target.host}:{target.port}; press a key to drive again"
                )
            )
            return

    def _cancel_reconnect(self) -> None:
        task, self._reconnect_task = self._reconnect_task, None
        if task is not None and task is not asyncio.current_task():
            task.cancel()

    def _spawn(self, coro: Any, name: str) -> None:
        task = asyncio.get_running_loop().create_task(coro, name=f"session-{name}")
        self._tasks.add(task)
        task.add_done_callback(self._task_done)

    def _spawn_detached(self, coro: Any) -> None:
        task = asyncio.get_running_loop().create_task(coro)
        task.add_done_callback(lambda t: t.cancelled() or t.exception())

    def _task_done(self, task: asyncio.Task[Any]) -> None:
        self._tasks.discard(task)
        if not task.cancelled() and task.exception() is not None:
            exc = task.exception()
            if not isinstance(exc, ClientError):
                log.error("session task %s failed", task.get_name(), exc_info=exc)

    # -- subscriptions -----------------------------------------------------------------------
    def _setup_subscriptions(self, client: AriaClient) -> None:
        self._held_subs.clear()
        for sub in applicable(self.subscriptions, client.supports):
            if sub.only_while is None:
                client.request(sub.name, sub.interval(self.config), partial(sub.handler, self))
        self._sync_subscriptions()
        self.ld.subscribe(client)
        for name, (interval, handler) in self._extra_subs.items():
            if client.supports(name):
                client.request(name, interval, handler)

    def _sync_subscriptions(self) -> None:
        """Start or end the conditional subscriptions (``only_while``) whose condition changed."""
        client = self.client
        if client is None or not client.connected:
            return
        for sub in applicable(self.subscriptions, client.supports):
            if sub.only_while is None:
                continue
            wanted = sub.only_while(self)
            if wanted and sub.name not in self._held_subs:
                self._held_subs.add(sub.name)
                client.request(sub.name, sub.interval(self.config), partial(sub.handler, self))
            elif not wanted and sub.name in self._held_subs:
                self._held_subs.discard(sub.name)
                client.stop_request(sub.name)

    def subscribe(self, name: str, interval_ms: int, handler: Callable[[Packet], None]) -> None:
        """An extra subscription, restored after every reconnect."""
        self._extra_subs[name] = (interval_ms, handler)
        if self.client is not None and self.client.connected:
            self.client.request(name, interval_ms, handler)

    def unsubscribe(self, name: str) -> None:
        self._extra_subs.pop(name, None)
        if self.client is not None:
            self.client.stop_request(name)

    async def _fetch_once_infos(self, client: AriaClient) -> None:
        timeout = self.config.reply_timeout
        with contextlib.suppress(ClientError, ProtocolError):
            if client.supports("batteryInfo"):
                info = (await client.request_once("batteryInfo", timeout=timeout)).decode()
                assert isinstance(info, BatteryInfo)
                self._robot_update(
                    battery_low=info.low_battery,
                    battery_shutdown=info.shutdown,
                    battery_is_soc=info.state_of_charge,
                )
            if client.supports("getSafeDrive"):
                self._on_safe_drive((await client.request_once("getSafeDrive", timeout=timeout)).payload)
        await self.ld.fetch(client)
        await self.nav.fetch_goals(client)
        await self.strings.connected(client)

    def _decode(self, name: str, payload: bytes) -> Any:
        try:
            return decode_payload(name, Side.REPLY, payload)
        except ProtocolError as exc:
            # Counted (the health shows it), logged sparingly: a 10 Hz stream of bad packets must
            # neither flood the log nor end the link; the next good packet is used as usual.
            self.health.bad_payloads += 1
            if self.health.bad_payloads <= 10 or self.health.bad_payloads % 1000 == 0:
                log.warning("undecodable %s packet (%d so far): %s", name, self.health.bad_payloads, exc)
            return None

    def _on_numbers(self, packet: Packet) -> None:
        numbers = self._decode(packet.name, packet.payload)
        if isinstance(numbers, UpdateNumbers):
            self._apply_numbers(numbers, packet.received_at)

    def _apply_numbers(self, n: UpdateNumbers, at: float) -> None:
        was_ok = self.health.level(at) is LinkLevel.OK
        self.health.note_status(at)
        self._robot_update(
            x=float(n.x), y=float(n.y), th=float(n.th), vel=float(n.vel), rot_vel=float(n.rot_vel),
            lat_vel=float(n.lat_vel), battery_v=n.battery,
            temperature=float(n.temperature) if n.temperature_known else None, numbers_at=at,
        )  # fmt: skip
        if not was_ok:
            self.kick()  # the link came back: re-evaluate at once

    def _on_strings(self, packet: Packet) -> None:
        s = self._decode(packet.name, packet.payload)
        if isinstance(s, UpdateStrings):
            self._robot_update(
                status=s.status, mode=s.mode, extended_status=s.extended_status, strings_at=packet.received_at
            )

    def _on_update(self, packet: Packet) -> None:
        u = self._decode(packet.name, packet.payload)
        if isinstance(u, Update):
            self._robot_update(status=u.status, mode=u.mode, strings_at=packet.received_at)
            self._apply_numbers(u.numbers, packet.received_at)

    def _on_mode_info(self, packet: Packet) -> None:
        m = self._decode(packet.name, packet.payload)
        if isinstance(m, ModeInfo):
            self._robot_update(mode_name=m.mode_name)

    def _on_safe_drive(self, payload: bytes) -> None:
        s = self._decode("getSafeDrive", payload)
        if isinstance(s, SafeDrive):
            self._robot_update(safe_drive=s.safe)

    def _on_sonar(self, packet: Packet) -> None:
        readings = self._decode(packet.name, packet.payload)
        if readings is not None and hasattr(readings, "readings"):
            self._robot_update(sonar=tuple(readings.readings), sonar_at=packet.received_at)

    def _on_map_updated(self, packet: Packet) -> None:
        if self.config.fetch_map:
            self._request_map()

    def _on_goals_updated(self, packet: Packet) -> None:
        client = self.client
        if client is not None:
            self.nav.on_goals_updated(client)
            self.ld.goals_updated(client)

    def _on_loc_state(self, packet: Packet) -> None:
        self.nav.on_loc_state(packet)

    def _on_path(self, packet: Packet) -> None:
        self.nav.on_path(packet)

    def _on_popup_create(self, packet: Packet) -> None:
        self.popups.on_create(packet)

    def _on_popup_close(self, packet: Packet) -> None:
        self.popups.on_close(packet)

    # -- the server's own commands (protocol §4.10) and popup answers ---------------------------
    async def list_commands(self) -> CommandCatalogue:
        """The simple and string commands this user may run (NotSupported where none are listed)."""
        return await list_commands(self._require_connected(), self.config.reply_timeout)

    async def run_command(self, command: ServerCommand, argument: str | None = None) -> bool:
        """Send it; True once the server answered a request sent after it (it has taken it)."""
        return await run_command(self._require_connected(), command, argument, self.config.reply_timeout)

    def answer_popup(self, popup_id: int, button: int) -> None:
        self.popups.click(popup_id, button)

    async def fetch_config(self) -> ServerConfig:
        return await fetch_config(self._require_connected(), self.config.reply_timeout)

    async def set_config(self, changes: dict[str, dict[str, str]]) -> Any:
        return await set_config(self._require_connected(), changes, self.config.reply_timeout)

    def _on_config_updated(self, packet: Packet) -> None:
        self.config_feed.on_updated(packet)

    def _require_connected(self) -> AriaClient:
        client = self.client
        if client is None or not client.connected:
            raise ServerClosed("not connected")
        return client

    def _navigating(self) -> bool:
        return self.nav.navigating

    def _goal_pose(self, name: str) -> tuple[float, float, float | None] | None:
        """The loaded map's goal called ``name``: (x, y, heading — only for a ``GoalWithHeading``)."""
        data = self._map.data
        if data is None or not name:
            return None
        for o in data.objects:
            if o.is_goal and o.name == name:
                return (o.x, o.y, o.th if o.type.lower() == "goalwithheading" else None)
        return None

    # -- RTT ---------------------------------------------------------------------------------
    async def _ping_loop(self, client: AriaClient) -> None:
        name = ping_data(client.datalist)
        if name is None:
            return
        while client.connected:
            started = time.perf_counter()
            try:
                reply = await client.request_once(name, timeout=self.health.ping_deadline(self.clock()))
            except ClientTimeout:
                # The server may have stopped reading: it would not hear a stop either.
                self.health.note_ping_timeout()
                self._publish_health()
                self.kick()
            except ClientError:
                return
            else:
                self.health.note_rtt(time.perf_counter() - started, self.clock())
                if name == "getSafeDrive":
                    self._on_safe_drive(reply.payload)
                self._publish_health()
            await asyncio.sleep(self.config.ping_interval)

    # -- the heart: drive governor + health, on exact deadlines -------------------------------
    def kick(self) -> None:
        """Run the heart now (the lease changed, or status came back). Loop thread only."""
        self._kick.set()

    def _ensure_heart(self) -> None:
        if self._heart_task is None or self._heart_task.done():
            self._heart_task = asyncio.get_running_loop().create_task(self._heart(), name="session-heart")

    async def step(self, timeout: float = STEP_TIMEOUT) -> None:
        """Wait until the heart has run once more (tests drive a fake clock with this).

        Raises :class:`ClientTimeout` if it has not run within ``timeout`` s.
        """
        self._ensure_heart()
        self._stepped.clear()
        self.kick()
        try:
            async with asyncio.timeout(timeout):
                await self._stepped.wait()
        except TimeoutError:
            raise ClientTimeout(f"the session heart did not run within {timeout:g} s") from None

    async def _heart(self) -> None:
        while True:
            self._kick.clear()
            now = self.clock()
            try:
                self._beat(now)
            except Exception:
                log.exception("session heart step failed")
            self._stepped.set()
            wake = min(self.governor.next_wakeup(now), self.health.next_change(now))
            delay = min(HEART_MAX_SLEEP, max(0.0, wake - self.clock()))
            due = self.clock() + delay
            with contextlib.suppress(TimeoutError):
                async with asyncio.timeout(delay):
                    await self._kick.wait()
            if not self._kick.is_set():  # woke by its timer: how late this machine ran it
                self.health.note_wake(self.clock() - due, self.clock())

    def _beat(self, now: float) -> None:
        self._poll_guardian()
        map_task = self._map_task
        if map_task is not None and not map_task.done() and self.client is not None:
            self.health.note_traffic(self.client.last_packet_at)  # map bytes keep the link alive
        else:
            self.health.traffic_done()
        level = self.health.level(now)
        link_ok = level is LinkLevel.OK and self.connected
        for action in self.governor.step(
            now, link_ok, lambda: f"{self.health.cause(now)}. {self.health.advice()}"
        ):
            if isinstance(action, SendRatios):
                r = action.ratios
                if self.guardian is not None:
                    self.guardian.arm()  # before the first ratioDrive of a drive
                self._send(RatioDrive(r.trans, r.rot, r.throttle, r.lat or None))
            elif isinstance(action, SendStop):
                self._send_stop(f"lease {action.reason.value}" + (f": {action.why}" if action.why else ""))
        self._publish_health(now)
        if level is LinkLevel.LOST and self.client is not None:
            target = self._target
            if target is not None and target.auto_reconnect:
                where = f"{target.host}:{target.port}"
                if self.health.requests_unanswered:
                    why = f"{where} answered none of the last {self.health.ping_failures} pings"
                else:
                    why = f"no status from {where} for {self.health.lost_after:g} s"
                self._connection_lost(ServerClosed(why))

    def _publish_health(self, now: float | None = None) -> None:
        now = self.clock() if now is None else now
        if self.client is None or not self.health.running:
            self._publish(HealthChanged(LinkHealth(rtt_ms=None)))
            return
        self._publish(HealthChanged(self.health.snapshot(now, self.client.drops)))

    def _send(self, what: str | Payload, *args: Any) -> bool:
        """Send if connected and offered; a typed payload names its data (``_send(RatioDrive(…))``)."""
        client = self.client
        name = what if isinstance(what, str) else payload_name(what)
        if client is None or not client.connected or not client.supports(name):
            return False
        try:
            client.send(what, *args)
        except ClientError:
            return False
        self.packets_sent += 1
        return True

    def _send_stop(self, reason: str = "") -> None:
        """Zero ratios, then ``stop`` — whatever the link health looks like. ``reason`` is for ``on_stop``."""
        sent = self._send(RatioDrive(0.0, 0.0, 0.0))
        sent = self._send("stop") or sent
        tap = self.on_stop
        if tap is not None:
            with contextlib.suppress(Exception):
                tap(reason or "stop", sent)
        if self.guardian is not None:
            self.guardian.disarm()

    # -- the guardian (rtmu.guardian): a stop that survives this process ----------------------
    def _start_guardian(self, target: _Target) -> None:
        self._close_guardian(goodbye=True)
        try:
            self.guardian = GuardianHandle.start(
                Hello(target.host, target.port, target.user, target.password, self.config.connect_timeout)
            )
        except OSError as exc:
            self._guardian_unavailable(f"it could not be started: {exc.strerror or exc}")
            return
        self._guardian_beat(self.guardian)

    def _guardian_beat(self, guardian: GuardianHandle) -> None:
        """The network thread's heartbeat to the guardian, every BEAT_PERIOD while it lives."""
        if self.guardian is not guardian:
            return
        guardian.beat_net()
        asyncio.get_running_loop().call_later(BEAT_PERIOD, self._guardian_beat, guardian)

    def _close_guardian(self, *, goodbye: bool) -> None:
        guardian, self.guardian = self.guardian, None
        if guardian is not None:
            guardian.close(goodbye=goodbye)

    def _poll_guardian(self) -> None:
        guardian = self.guardian
        if guardian is None:
            return
        for word, text in guardian.poll():
            if word == "stopped":
                # It stopped the robot (we were frozen, or too slow): no drive resumes without a fresh press.
                self.lease.end(EndReason.STOPPED)
                self._notice(Notice.error(Kind.SAFETY, f"The guardian stopped the robot: {text}"))
            elif word in ("unavailable", "lost", "ended"):
                self.guardian = None
                guardian.close(goodbye=True)
                self._guardian_unavailable(text)

    def _guardian_unavailable(self, reason: str) -> None:
        self._notice(
            Notice.warning(
                Kind.SAFETY,
                f"Guardian not available ({reason}): if this window is killed or frozen while driving, "
                "only the server's own 2 s watchdog stops the robot",
            )
        )

    # -- operator commands -------------------------------------------------------------------
    def stop_now(self) -> None:
        """The stop key: always sent at once, even when the link looks stale."""
        self.lease.end(EndReason.STOPPED)
        self._send_stop("stop key")
        self.governor.reset()
        self.kick()

    async def stop_and_flush(self, timeout: float = 0.5) -> bool:
        """:meth:`stop_now`, then wait (bounded) until the stop has been handed to the kernel.

        True when it has (or there was no connection to stop); for callers about to freeze the
        process (Ctrl-Z) or end it abruptly.
        """
        self.stop_now()
        client = self.client
        if client is None or not client.connected:
            return True
        return await client.flush(timeout)

    def command(self, what: str | Payload, *args: Any) -> None:
        """Fire-and-forget request-once: ``command(TurnByAngle(90))``, or a name and arguments."""
        client = self._require(what if isinstance(what, str) else payload_name(what))
        client.send(what, *args)

    # -- navigation: the server drives (ARNL) -------------------------------------------------
    def navigate(self, payload: Payload) -> None:
        """Send a navigation command (:class:`GotoGoal`, :class:`GotoPose`, :class:`Home`, :class:`Dock`,
        :class:`TourGoals`, :class:`LocalizeToPose`); NotSupported where the server does not list it.

        A drive in progress ends first (zero ratios + ``stop`` go out before the command): the
        next ``ratioDrive`` would otherwise take the robot back from the server at once.
        """
        name = payload_name(payload)
        client = self._require_nav(name)
        if not isinstance(payload, LocalizeToPose):
            driving = self.governor.driving
            self.lease.end(EndReason.STOPPED)
            if driving:
                self._send_stop("navigation takes over")
                self.governor.reset()
        client.send(payload)
        self.packets_sent += 1
        self.nav.sent(payload)

    def goto_goal(self, name: str) -> None:
        self.navigate(GotoGoal(name))

    def goto_pose(self, x: float, y: float, th: float | None = None) -> None:
        self.navigate(GotoPose(round(x), round(y), None if th is None else round(th)))

    def home(self) -> None:
        self.navigate(Home())

    def dock(self) -> None:
        self.navigate(Dock())

    def tour_goals(self) -> None:
        self.navigate(TourGoals())

    def localize(self, x: float, y: float, th: float) -> None:
        self.navigate(LocalizeToPose(round(x), round(y), round(th)))

    def _require_nav(self, name: str) -> AriaClient:
        client = self.client
        if client is None or not client.connected:
            raise ServerClosed("not connected")
        if not client.supports(name):
            raise NotSupported(name, f"this server does not navigate that way (it does not offer {name})")
        return client

    def set_safe_drive(self, on: bool) -> None:
        client = self._require("setSafeDrive")
        client.send(SetSafeDrive(on))
        if client.supports("getSafeDrive"):
            self._spawn(self._refresh_safe_drive(client), "safe-drive")

    async def _refresh_safe_drive(self, client: AriaClient) -> None:
        reply = await client.request_once("getSafeDrive", timeout=self.config.reply_timeout)
        self._on_safe_drive(reply.payload)

    def image_source(self) -> str | None:
        client = self.client
        if client is None:
            return None
        names = sorted(e.name for e in client.datalist if e.name.startswith("getPicture"))
        if names:
            return names[0]
        return "sendVideo" if client.supports("sendVideo") else None

    async def request_image(self) -> CameraImage:
        """One camera picture; also published as the model's ``camera`` part."""
        source = self.image_source()
        if source is None:
            raise NotSupported(
                "getPicture", "this server offers no camera pictures (getPicture… or sendVideo)"
            )
        client = self._require(source)
        reply = await client.request_once(source, timeout=self.config.reply_timeout)
        if payload_type_for(source, Side.REPLY) is None:
            raise NotSupported(source, f"RTMU cannot decode {source!r} pictures")
        try:
            picture = reply.decode()
        except MalformedReply:
            self.health.bad_payloads += 1
            raise
        self._image_sequence += 1
        image = CameraImage(
            jpeg=bytes(picture.jpeg),  # type: ignore[attr-defined]
            width=int(picture.width),  # type: ignore[attr-defined]
            height=int(picture.height),  # type: ignore[attr-defined]
            source=source,
            received_at=reply.received_at,
            sequence=self._image_sequence,
            stamp_ns=frame_stamp(bytes(picture.jpeg)),  # type: ignore[attr-defined]
        )
        self._publish(CameraChanged(image))
        return image

    def _require(self, name: str) -> AriaClient:
        client = self.client
        if client is None or not client.connected:
            raise ServerClosed("not connected")
        if not client.supports(name):
            raise NotSupported(name)
        return client

    # -- map ---------------------------------------------------------------------------------
    async def load_map(self) -> MapModel:
        """Download the map (``getMapBinary`` when offered, else ``getMap``), publish it, return it.

        Requests merge: while a download is in flight, asking again (this call, or any number
        of ``mapUpdated`` broadcasts) only marks the map dirty, and ONE more download starts
        when the current one ends — a storm of broadcasts costs two downloads, not hundreds.
        """
        client = self.client
        if client is None or not client.connected:
            raise ServerClosed("not connected")
        return await asyncio.shield(self._request_map())

    def _request_map(self) -> asyncio.Task[MapModel]:
        task = self._map_task
        if task is not None and not task.done():
            self._map_dirty = True
            return task
        self._map_dirty = False
        task = self._map_task = asyncio.get_running_loop().create_task(self._map_loader(), name="session-map")
        self._tasks.add(task)
        task.add_done_callback(self._task_done)
        return task

    async def _map_loader(self) -> MapModel:
        while True:
            self._map_dirty = False
            result = await self._load_map_once()
            if not self._map_dirty or not self.connected:
                return result

    async def _load_map_once(self) -> MapModel:
        client = self.client
        if client is None or not client.connected:
            raise ServerClosed("not connected")
        if map_source(client) is None:
            self._set_map(MapModel(state=MapPhase.UNSUPPORTED))
            return self._map
        target = self._target
        key = None
        if target is not None:
            key = await map_key(client, target.host, target.port, self.config.reply_timeout)
        cached = self._map_cache.get(key)
        if cached is not None:  # the same map as last time (reconnect, spurious mapUpdated)
            self.map_downloads_skipped += 1
            if cached != self._map or cached.data is not self._map.data:
                self._set_map(cached)
            return self._map
        shared, content = self.config.shared_maps, content_key(key)
        if shared is None or content is None:
            return await self._download_map(client, key)
        found, pending = shared.claim(content)
        if pending is not None:
            found = await shared.wait(pending)
        if found is None:
            if pending is not None:  # the other download failed: this session fetches its own
                return await self._download_map(client, key)
            model = None
            try:
                model = await self._download_map(client, key)
            finally:
                shared.finish(content, model if model is not None and model.state == MapPhase.READY else None)
            return model
        if not client.connected:
            raise ServerClosed("not connected")
        self.map_downloads_shared += 1
        self._set_map(replace(found, generation=self._map.generation + 1))
        self._map_cache.put(key, self._map)
        return self._map

    async def _download_map(self, client: AriaClient, key: MapKey | None) -> MapModel:
        generation = self._map.generation
        self._set_map(MapModel(state=MapPhase.LOADING, name=self._map.name, generation=generation))

        def progress(count: int) -> None:
            self._set_map(replace(self._map, received=count))

        try:
            got = await download_map(client, timeout=self.config.reply_timeout, progress=progress)
        except ProtocolFault as exc:  # the map itself is at fault: keep the verdict for this map
            failed = self._map_failed(client, str(exc))
            self._map_cache.put(key, failed)
            return failed
        except ClientError as exc:
            return self._map_failed(client, str(exc))
        except Exception as exc:  # a bug must still end "loading": the window would wait for ever
            log.exception("loading the map failed")
            return self._map_failed(client, f"internal error: {exc}")
        if got.data is None:
            self._set_map(
                MapModel(state=MapPhase.NONE, name=got.name, generation=generation, received=got.packets)
            )
            return self._map
        self._set_map(
            MapModel(
                state=MapPhase.READY,
                data=got.data,
                name=got.name,
                generation=generation + 1,
                received=got.packets,
            )
        )
        self._map_cache.put(key, self._map)
        return self._map

    def _map_failed(self, client: AriaClient, reason: str) -> MapModel:
        self._set_map(replace(self._map, state=MapPhase.FAILED, error=reason))
        if client.connected:
            self._notice(Notice.warning(Kind.MAP, f"The map could not be loaded: {reason}"))
        return self._map


SessionSubscription = Subscription[Session, SessionConfig]

SUBSCRIPTIONS: tuple[SessionSubscription, ...] = (
    Subscription("updateNumbers", lambda c: c.status_interval_ms, Session._on_numbers),
    Subscription("updateStrings", -1, Session._on_strings, needs="updateNumbers"),
    Subscription("update", lambda c: c.status_interval_ms, Session._on_update, unless="updateNumbers"),
    Subscription("getModeInfo", -1, Session._on_mode_info),
    Subscription("mapUpdated", -1, Session._on_map_updated),
    Subscription("sonarCurrent", lambda c: c.sonar_interval_ms, Session._on_sonar),
    Subscription("getLocState", lambda c: c.loc_state_interval_ms, Session._on_loc_state),
    Subscription("goalsUpdated", -1, Session._on_goals_updated, needs="getGoals"),
    Subscription("getPath", lambda c: c.path_interval_ms, Session._on_path, only_while=Session._navigating),
    Subscription("popupCreate", -1, Session._on_popup_create),
    Subscription("popupClose", -1, Session._on_popup_close),
    Subscription("configUpdated", -1, Session._on_config_updated),
)
"""What a session subscribes to on every connection, in this order, where the server offers it."""

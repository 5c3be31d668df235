"""The simulator's asyncio TCP server: sessions over the sans-I/O codec, a 10 ms cycle, a world.

Like ARIA's ``ArServerBase``: every client gets its own session (its
subscriptions: data number → interval, arguments, last time served); a cycle
every 10 ms steps the world and sends what is due; broadcasts go only to
clients subscribed to that data. A client that vanishes, sends garbage or
stops reading costs the others nothing: its bytes are decoded (and dropped)
by its own codec a slice at a time between everybody else's turns, maps are
sent to it only as fast as it reads them, and output that it does not drain
(past a few MB, or stuck for the backup timeout) gets it disconnected. Camera
frames are shared between clients and rendered off the loop (:mod:`.video`).
"""

from __future__ import annotations

import asyncio
import contextlib
import hashlib
import logging
import math
import random
import time
from collections import deque
from collections.abc import Callable
from itertools import count

import numpy as np

from rtmu.protocol.auth import UserTable
from rtmu.protocol.commands import RejectReason
from rtmu.protocol.datalist import DataList
from rtmu.protocol.packet import encode_packet
from rtmu.protocol.payloads.ld import DockInfoChanged

from . import switch
from .arconfig import SimArConfig
from .catalogue import Row, custom_commands
from .config import SimConfig
from .files_data import add_default_folder
from .geometry import Obstacles
from .handlers import (
    BROADCAST_ONLY,
    Call,
    Other,
    Stream,
    mode_info_payload,
    popup_close_payload,
    popup_payload,
    strings_payload,
)
from .heard import RequestLog
from .mapserve import ServedMap, load_map
from .navmodes import NavMap
from .profiles import get_profile
from .sim_client import READ_CHUNK, SimClient, SimServerConnection
from .video import VideoFeed
from .world import PHYSICS_DT, World, free_spot_near

log = logging.getLogger("rtmu.sim")

CYCLE_S = 0.01
"""ARIA's server loop sleeps 10 ms between cycles."""
MAX_CATCH_UP_STEPS = 50
WARM_STREAMS_ABOVE_LINES = 100_000
REFUSING_SLOTS = 16
"""Connections beyond ``max_clients`` that are kept long enough to be told reason 5; past these, a new
connection is closed at once (each one costs a socket and a codec until it introduces itself)."""
KEY_RNG = random.SystemRandom()
"""Password, auth and intro keys come from the OS, never from ``--seed``: a seeded key would repeat on
every restart, and a recorded login could then be replayed. The seed drives physics, wander and noise."""


class SimServer:
    def __init__(self, config: SimConfig | None = None) -> None:
        self.config = config or SimConfig()
        cfg = self.config
        self.profile = get_profile(cfg.profile)
        if cfg.protocol_version is None:
            cfg.protocol_version = self.profile.protocol_version
        cfg.camera = cfg.camera and self.profile.camera
        self.handlers = self.profile.handler_table()
        self._module_commands = tuple(r for r in self.profile.module_parts()[0] if r[4] == "CustomCommands")
        self.map: ServedMap = self._load_map(cfg.map_path)
        self.file_md5 = self.map.md5
        """MD5 of the map file as last read (or written): ``checkMap`` reloads only when the file differs."""
        obstacles = self.map.obstacles()
        home = cfg.start_pose or self.map.home
        x, y = free_spot_near(obstacles, home[0], home[1], 250.0) if self.map.present else (home[0], home[1])
        self.world = World(
            obstacles,
            home=(x, y, home[2]),
            access_point=self.map.access_point,
            seed=cfg.seed,
            drive_timeout=cfg.drive_timeout,
            battery_v=cfg.battery_v,
        )
        self.home = (x, y, home[2])
        self.world.nav_map = self._nav_map()
        self.datalist: DataList = self.profile.catalogue(camera=cfg.camera, test_hooks=cfg.test_hooks)
        if cfg.files_default_dir is not None:
            add_default_folder(self.datalist, self.handlers, cfg.files_default_dir)
        self.users: UserTable | None = UserTable.load(cfg.users_path) if cfg.users_path else None
        self.sessions: list[SimClient] = []
        self.stop_log: deque[tuple[float, int, str]] = deque(maxlen=1000)
        """Every ``stop`` received: (world time, session ident, the client's self identifier)."""
        self.heard = RequestLog()
        """Every request of every connection, by name (tests: no observer ever sent a motion request)."""
        self._ids = count(1)
        self._server: asyncio.base_events.Server | None = None
        self._cycle_task: asyncio.Task[None] | None = None
        self._tasks: set[asyncio.Task[None]] = set()
        self._cycle_cache: dict[str, bytes] = {}
        self._real_start = 0.0
        self._steps_done = 0
        self.port = 0
        self.cycles = 0
        self.malformed_packets = 0
        """Control packets from any client that did not decode (each refused or ignored, never raised)."""
        self.cpu = CpuMeter()
        self.video_size: tuple[int, int] = cfg.camera_size
        self.arconfig = SimArConfig(self, cfg.config_filler)
        threaded = cfg.realtime if cfg.render_in_thread is None else cfg.render_in_thread
        self.video = VideoFeed(threaded=threaded, period=1.0 / max(cfg.camera_hz, 0.1))
        self._switch_task: asyncio.Task[None] | None = None
        self.central_heartbeats: switch.Heartbeats | None = None
        """The central server's heartbeats, heard while switched to one (``switch_to``)."""
        if cfg.switch_to is not None:
            self.central_heartbeats = switch.add_switch_data(self.datalist, self.handlers)
            if cfg.central_server is None:  # as ARIA's robot servers do: direct logins get reason 2
                cfg.central_server = switch.parse_address(cfg.switch_to)[0]

    @property
    def robot(self):
        return RobotView(self.world)

    # -- lifetime ----------------------------------------------------------------------
    async def start(self) -> None:
        cfg = self.config
        self._server = await asyncio.start_server(self._accept, cfg.host, cfg.port, limit=READ_CHUNK)
        sock = self._server.sockets[0]
        self.port = sock.getsockname()[1]
        self._real_start = time.monotonic()
        if cfg.realtime:
            self._cycle_task = asyncio.create_task(self._run_realtime(), name="rtmu-sim-cycle")
            nav = self.world.nav_map
            if nav is not None:  # a big map's planning grid takes a second: not in the first gotoGoal
                asyncio.get_running_loop().run_in_executor(None, nav.grid)
            if len(self.map.lines) > WARM_STREAMS_ABOVE_LINES:
                # Frame a big map's streams on a worker thread now, not in the first client's request.
                loop = asyncio.get_running_loop()
                for name, make in (
                    ("getMap", self.map.text_stream),
                    ("getMapBinary", self.map.binary_stream),
                ):
                    number = self.datalist.number(name)
                    if number is not None:
                        loop.run_in_executor(None, make, number)
        if cfg.switch_to is not None:
            host, port = switch.parse_address(cfg.switch_to)
            switching = switch.switch_loop(
                host,
                port,
                cfg.switch_name,
                cfg.switch_retry,
                self.serve_switched,
                self.central_heartbeats,
                cfg.switch_silence,
            )
            self._switch_task = asyncio.create_task(switching, name="rtmu-sim-switch")

    async def stop(self) -> None:
        """Say SHUTDOWN to every client, let the bytes go, close everything."""
        self._stop_switching()
        if self._cycle_task is not None:
            self._cycle_task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await self._cycle_task
            self._cycle_task = None
        await self.video.settle()
        self.video.close()
        if self._server is not None:
            self._server.close()
        for s in list(self.sessions):
            s.cancel_download()
            s.conn.shutdown()
            s.flush_codec()
            s.closed = True
            with contextlib.suppress(Exception):
                s.writer.close()
        for s in list(self.sessions):
            with contextlib.suppress(Exception):
                await asyncio.wait_for(s.writer.wait_closed(), 1.0)
        self.sessions.clear()
        if self._tasks:
            await asyncio.wait(list(self._tasks), timeout=1.0)
        for task in list(self._tasks):
            task.cancel()
        if self._server is not None:
            with contextlib.suppress(Exception):
                await asyncio.wait_for(self._server.wait_closed(), 1.0)
            self._server = None

    def kill(self) -> None:
        """Die abruptly: no SHUTDOWN, sockets reset (for lost-link tests)."""
        self._stop_switching()
        if self._cycle_task is not None:
            self._cycle_task.cancel()
            self._cycle_task = None
        if self._server is not None:
            self._server.close()
        self.video.close()
        for s in list(self.sessions):
            s.abort()

    def _stop_switching(self) -> None:
        if self._switch_task is not None:
            self._switch_task.cancel()
            self._switch_task = None

    async def serve_switched(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        """Serve the socket a central server accepted our switch on: its login is never refused as direct."""
        await self._serve(reader, writer, None)

    def forget(self, session: SimClient) -> None:
        with contextlib.suppress(ValueError):
            self.sessions.remove(session)

    async def _accept(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        cfg = self.config
        if cfg.max_clients is not None and len(self.sessions) >= cfg.max_clients + REFUSING_SLOTS:
            log.info("%d connections open; closing a new one at once", len(self.sessions))
            transport = writer.transport
            if transport is not None:
                transport.abort()
            return
        general: tuple[int, str] | None = None
        if cfg.central_server is not None:
            general = (int(RejectReason.USING_CENTRAL_SERVER), cfg.central_server)
        elif cfg.max_clients is not None and len(self.sessions) >= cfg.max_clients:
            general = (
                int(RejectReason.TOO_MANY_CLIENTS),
                "Server rejecting connection since it would exceed the maximum number of allowed "
                f"connections (which is {cfg.max_clients})",
            )
        await self._serve(reader, writer, general)

    async def _serve(
        self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter, general: tuple[int, str] | None
    ) -> None:
        cfg = self.config
        conn = SimServerConnection(
            self.datalist,
            self.users,
            server_key=cfg.server_key,
            udp_port=0,
            rng=KEY_RNG,
            protocol_version=cfg.protocol_version or "",
            general_reject=general,
            config=cfg,
        )
        session = SimClient(self, next(self._ids), reader, writer, conn)
        self.sessions.append(session)
        task = asyncio.current_task()
        if task is not None:
            self._tasks.add(task)
        try:
            await session.run()
        except asyncio.CancelledError:
            pass  # the server is stopping; asyncio's stream callback would log a cancelled handler
        finally:
            if task is not None:
                self._tasks.discard(task)

    # -- serving ------------------------------------------------------------------------
    def cycle_cached(self, key: str, make: Callable[[], bytes]) -> bytes:
        """One payload per cycle however many clients ask (status, sonar)."""
        value = self._cycle_cache.get(key)
        if value is None:
            value = make()
            self._cycle_cache[key] = value
        return value

    def invoke(self, session: SimClient, number: int, name: str, args: bytes, *, once: bool) -> None:
        handler = self.handlers.get(name)
        if handler is None:
            return
        replies = handler(Call(self, session, name, number, args, once))
        for reply in replies:
            if isinstance(reply, bytes):
                session.send(number, reply)
            elif isinstance(reply, Stream):
                session.stream(number, reply.chunks)
            elif isinstance(reply, Other):
                other = self.datalist.number(reply.name)
                if other is not None:
                    session.send(other, reply.payload)

    def broadcast(self, name: str, payload: bytes = b"", exclude: object | None = None) -> int:
        """Send data ``name`` to every client subscribed to it (but ``exclude``); returns how many got it."""
        number = self.datalist.number(name)
        if number is None:
            return 0
        packet = encode_packet(number, payload)
        sent = 0
        for s in list(self.sessions):
            if number in s.subscriptions and not s.closed and s is not exclude:
                s.write(packet)
                sent += 1
        return sent

    def _serve_due(self) -> None:
        now = self.world.time
        limit = self.config.skip_periodic_above
        for s in list(self.sessions):
            if s.closed or not s.subscriptions:
                continue
            backlog = s.buffered > limit
            for number, sub in list(s.subscriptions.items()):
                if sub.interval_ms == -1 or sub.name in BROADCAST_ONLY:
                    continue
                if sub.interval_ms > 0 and (now - sub.last) * 1000.0 < sub.interval_ms - 1e-6:
                    continue
                sub.last = now
                if backlog:
                    continue  # like a lost UDP packet: a client that is behind misses this one
                self.invoke(s, number, sub.name, sub.args, once=False)
                if s.closed:
                    break

    def broadcast_changes(self) -> None:
        ch = self.world.changes
        if ch.mode_info:
            self.broadcast("getModeInfo", mode_info_payload(self.world))
        if ch.strings:
            self.broadcast("updateStrings", strings_payload(self.world))
        if ch.dock_info:
            self.broadcast("dockInfoChanged", DockInfoChanged(self.world.dock_mode.state).encode())
        for popup in ch.popups_created:
            self.broadcast("popupCreate", popup_payload(popup))
        for popup_id, text in ch.popups_closed:
            self.broadcast("popupClose", popup_close_payload(popup_id, text))
        ch.clear()

    def cycle(self) -> None:
        """One server cycle (10 ms of simulated time): step, broadcast what changed, send what is due."""
        for _ in range(round(CYCLE_S / PHYSICS_DT)):
            self.world.step(PHYSICS_DT)
        self._cycle_cache.clear()
        self.broadcast_changes()
        self._serve_due()
        self.cpu.sample()
        now = self.clock()
        for s in list(self.sessions):
            s.check_health(now)
        self.cycles += 1

    async def advance(self, seconds: float) -> None:
        """Manual clock: run the cycles that fit in ``seconds`` of simulated time, sending as they go."""
        for _ in range(3):
            await asyncio.sleep(0)  # let bytes already received be handled first
        n = max(math.floor(seconds / CYCLE_S + 1e-9), 0)
        for i in range(n):
            self.cycle()
            if i % 10 == 9:
                await asyncio.sleep(0)
        await asyncio.sleep(0)

    async def _run_realtime(self) -> None:
        cycles_done = 0
        start = time.monotonic()
        while True:
            due = int((time.monotonic() - start) / CYCLE_S)
            behind = due - cycles_done
            if behind > MAX_CATCH_UP_STEPS:  # we were starved: skip time rather than race
                cycles_done = due - MAX_CATCH_UP_STEPS
                behind = MAX_CATCH_UP_STEPS
            for _ in range(max(behind, 0)):
                try:
                    self.cycle()
                except Exception:
                    log.exception("simulator cycle failed")
                cycles_done += 1
            await asyncio.sleep(CYCLE_S)

    def clock(self) -> float:
        """Seconds for connection deadlines: wall time, or simulated time on the manual clock."""
        return time.monotonic() if self.config.realtime else self.world.time

    def custom_commands(self) -> tuple[Row, ...]:
        """serverDemo's simple commands, then the ones the profile's data modules add (those it lists)."""
        rows = custom_commands(self.config.camera) + self._module_commands
        return tuple(r for r in rows if r[0] in self.datalist)

    def video_trailer(self) -> bytes:
        """The 2 bytes ARIA's video forwarder leaves after a picture (the upstream packet's checksum)."""
        return b"\x5a\xa5" if self.config.video_trailer else b""

    def check_map(self) -> bool:
        """ARIA's ``checkMap``: reload the map file if it changed, move the robot home, tell subscribers."""
        path = self.config.map_path
        if path is None or not path.is_file():
            return False
        raw_md5 = hashlib.md5(path.read_bytes()).digest()
        if raw_md5 == self.file_md5:
            return False
        self.file_md5 = raw_md5
        self.install_map(self._load_map(path), move_home=True)
        return True

    def install_map(
        self, served: ServedMap, *, move_home: bool = False, obstacles: Obstacles | None = None
    ) -> None:
        """Serve ``served`` from now on (walls, navigation's grid, home); ``mapUpdated`` and ``goalsUpdated``
        to every subscriber. ``move_home``: the robot starts again at the new map's home (``checkMap``)."""
        self.map = self._profiled(served)
        obstacles = obstacles or self.map.obstacles()
        home = self.config.start_pose or self.map.home
        x, y = free_spot_near(obstacles, home[0], home[1], 250.0)
        self.home = (x, y, home[2])
        if obstacles is not self.world.obstacles:
            self.world.replace_obstacles(obstacles)
        self.world.nav_map = nav = self._nav_map()
        self.world.home = self.home
        if move_home:
            self.reset_pose()
        if nav is not None and self.config.realtime:  # the new grid built aside, not in the next plan
            asyncio.get_running_loop().run_in_executor(None, nav.grid)
        self.broadcast("mapUpdated")
        self.broadcast("goalsUpdated")

    def _load_map(self, path):
        """The map file, served with the profile's first line (an LD robot's ``2D-Map-Ex4``)."""
        return self._profiled(load_map(path))

    def _profiled(self, served: ServedMap) -> ServedMap:
        header = self.profile.map_header
        if header and served.present and served.lines:
            served.lines[0] = header
            if served.header:
                served.header[0] = header
        return served

    def _nav_map(self) -> NavMap | None:
        """What navigation plans on: the served map's walls and cairns (None without a map)."""
        m = self.map
        if not m.present:
            return None
        return NavMap(m.md5, m.segments, m.points, m.objects)

    # -- tools for tests and the demo -------------------------------------------------------
    def lose_localization(self) -> None:
        """The robot is lost (as ``SimulatorLoseLocalization``): navigation fails until ``localizeToPose``."""
        self.world.lose_localization()
        self.broadcast_changes()

    def place_obstacle(self, x1: float, y1: float, x2: float, y2: float) -> None:
        """A wall the map does not show (a trolley in the corridor): only the sonar will find it."""
        self.world.add_obstacles(np.array([[x1, y1, x2, y2]], dtype=np.float64))

    def reset_pose(self) -> None:
        b = self.world.body
        b.x, b.y, b.th = self.home
        b.vel = b.rot_vel = 0.0
        b.stalled = False
        self.world.dock_mode.leave()  # put back on its home cairn, it is on no dock
        self.world.stop()


class CpuMeter:
    """This process's CPU use in percent over the last second (what ARIA's ``CPU Use`` string shows)."""

    def __init__(self) -> None:
        self._t0 = time.monotonic()
        self._c0 = time.process_time()
        self.percent = 0.0

    def sample(self) -> None:
        t = time.monotonic()
        if t - self._t0 >= 1.0:
            c = time.process_time()
            self.percent = 100.0 * (c - self._c0) / (t - self._t0)
            self._t0, self._c0 = t, c


class RobotView:
    """``server.robot``: the live state by the names the API promises.

    x, y (mm), th (deg), vel (mm/s), rot_vel (deg/s), battery_v, status, mode (display string),
    mode_name, the ratio-drive mode's current ratios (trans_ratio, rot_ratio, throttle, lat_ratio —
    zeroed by the watchdog, as ARIA does) and the last ratioDrive as received (received_ratios,
    received_throttle, ratio_drives_received), safe_drive, stalled, collisions, watchdog_stops.
    """

    def __init__(self, world: World) -> None:
        self._world = world

    def __getattr__(self, name: str):
        w = self._world
        b, r = w.body, w.ratio_mode
        table = {
            "x": lambda: b.x,
            "y": lambda: b.y,
            "th": lambda: b.th,
            "vel": lambda: b.vel,
            "rot_vel": lambda: b.rot_vel,
            "battery_v": lambda: b.battery_v,
            "status": lambda: w.strings()[0],
            "mode": lambda: w.strings()[1],
            "mode_name": lambda: w.mode.NAME,
            "trans_ratio": lambda: r.trans_ratio,
            "rot_ratio": lambda: r.rot_ratio,
            "throttle": lambda: r.throttle_ratio,
            "throttle_ratio": lambda: r.throttle_ratio,
            "lat_ratio": lambda: r.lat_ratio,
            "safe_drive": lambda: r.safe,
            "stalled": lambda: b.stalled,
            "collisions": lambda: b.collisions,
            "watchdog_stops": lambda: r.timeouts,
            "last_drive_time": lambda: r.last_command,
            "received_ratios": lambda: w.received_ratios,
            "received_throttle": lambda: None if w.received_ratios is None else w.received_ratios[2],
            "ratio_drives_received": lambda: w.ratio_drives_received,
        }
        if name in table:
            return table[name]()
        raise AttributeError(name)

"""The pan-tilt-zoom camera head of one session (``ArServerHandlerCamera``, protocol §4.6).

After login :class:`PtzFeed` reads ``getCameraList``, picks the first camera whose list names a
``setCameraRel`` or ``setCameraAbs`` data the server also lists, and reads its limits
(``getCameraInfo<N>``) and position (``getCameraData<N>``) once. The position is then polled only
while someone looks at it (the camera page is shown): a hidden page costs the robot nothing. Where
there is no such camera the published :class:`~rtmu.values.state.PtzState` says why, so the window can
grey its controls with the reason. Moving the head is camera work, never robot motion: it needs
no drive lease. Every name and number comes from the server and is bounded before it is kept.
"""

from __future__ import annotations

import asyncio
import contextlib
import math
import time
from collections.abc import Callable
from dataclasses import replace
from typing import ClassVar

from ..protocol.errors import ProtocolError
from ..protocol.payloads.camera import Camera, CameraData, CameraInfo, CameraList, SetCameraAbs, SetCameraRel
from ..values.intents import Intent, PtzMove, WatchPtz
from ..values.state import PtzState
from .call_values import Packet
from .connection import AriaClient
from .errors import ClientError, NotSupported
from .feed import Feed, FeedContext

POLL_MS = 250
"""``getCameraData`` period while watched (ARIA suggests 100 ms; 4 Hz is plenty for a label)."""
HEAD_SPEEDS = (90.0, 69.0, 50.0)
"""Pan and tilt in degrees per second, zoom in % of its range per second: the fastest a VC-C4 turns
(ARIA's default slews for it). ARIA's VC-C4 driver reports the position it last asked for, not where
the head is, so a move is called settled no sooner than the head could have got there."""
FOLLOW_LIMIT_S = 15.0
"""A move is followed (read every ``POLL_MS``) at most this long; then the last reading stands."""
MAX_NAME = 64
"""Characters kept of a camera's name, type or display name."""
NO_LIST = "the server lists no cameras (getCameraList)"
NO_HEAD = "the server's cameras have no pan/tilt/zoom head (no setCameraRel / setCameraAbs)"
LIMIT = 327.67
"""The largest angle a ``byte2`` hundredth can carry."""


def _clip(text: str) -> str:
    return text if len(text) <= MAX_NAME else text[: MAX_NAME - 1] + "…"


def _finite(*values: float | None) -> bool:
    return all(v is None or (math.isfinite(v) and abs(v) <= LIMIT) for v in values)


def pick_camera(cameras: tuple[Camera, ...], offered: Callable[[str], bool]) -> Camera | None:
    """The first camera that can be moved: its list names a set command the server offers."""
    for cam in cameras:
        for command in ("setCameraRel", "setCameraAbs"):
            name = cam.data_name(command)
            if name and offered(name):
                return cam
    return None


class PtzFeed(Feed):
    """One session's PTZ head, published with the robot as ``RobotState.ptz``."""

    handles: ClassVar[tuple[type[Intent], ...]] = (PtzMove, WatchPtz)

    def __init__(self, ctx: FeedContext) -> None:
        super().__init__(ctx)
        self._timeout = ctx.config.reply_timeout
        self._client: AriaClient | None = None
        self._camera: Camera | None = None
        self._state = PtzState()
        self._polling = False
        self._move_no = 0
        """Counts moves: a newer move ends the following of an older one."""
        self.cameras: tuple[Camera, ...] = ()
        """Every camera the server listed (for ``rtmu ptz``), bounded by the packet."""
        self.read_error: ClientError | ProtocolError | None = None
        """Why the last camera list could not be read (the window shows it as the reason; ``rtmu ptz``
        exits with its own code: a lost link is not "no camera head")."""
        self.watching = False
        """Someone shows the position (the camera page): poll ``getCameraData`` while True."""

    @property
    def state(self) -> PtzState:
        return self._state

    def _set(self, state: PtzState) -> None:
        self._state = state
        self.ctx.robot_update(ptz=state)

    def connected(self, client: AriaClient) -> None:
        self.ctx.spawn(self.read_head(client), "ptz")

    async def read_head(self, client: AriaClient) -> None:
        """Read the camera list, limits and position once after login."""
        self._client, self._camera, self._polling, self.cameras = client, None, False, ()
        self.read_error = None
        if not client.supports("getCameraList"):
            self._set(PtzState(reason=NO_LIST))
            return
        try:
            reply = await client.request_once("getCameraList", timeout=self._timeout)
            cameras = CameraList.decode(reply.payload).cameras
        except (ClientError, ProtocolError) as exc:
            if client is self._client:
                self.read_error = exc
                self._set(PtzState(reason=f"the camera list could not be read: {exc}"))
            return
        if client is not self._client:
            return  # a newer connection has started reading its own list
        self.cameras = cameras
        cam = pick_camera(cameras, client.supports)
        if cam is None:
            self._set(PtzState(reason=NO_HEAD if cameras else NO_LIST))
            return
        self._camera = cam
        state = PtzState(
            camera=_clip(cam.name),
            display_name=_clip(cam.display_name or cam.name),
            camera_type=_clip(cam.camera_type),
            can_rel=self._offers("setCameraRel"),
            can_abs=self._offers("setCameraAbs"),
        )
        info_name = self._name("getCameraInfo")
        if info_name:
            with contextlib.suppress(ClientError, ProtocolError):
                info = CameraInfo.decode(
                    (await client.request_once(info_name, timeout=self._timeout)).payload
                )
                if _finite(
                    info.min_pan, info.max_pan, info.min_tilt, info.max_tilt, info.min_zoom, info.max_zoom
                ):
                    state = replace(
                        state,
                        pan_range=(info.min_pan, info.max_pan),
                        tilt_range=(info.min_tilt, info.max_tilt),
                        zoom_range=(info.min_zoom, info.max_zoom),
                        zoom_available=info.zoom_available,
                    )
        if client is not self._client:
            return
        self._set(state)
        await self.refresh()
        self._sync()

    def disconnected(self) -> None:
        self._client, self._camera, self._polling = None, None, False
        self._move_no += 1
        self._state = PtzState()
        self.ctx.robot_update(ptz=None)  # unknown until the next login reads the list

    def handle(self, intent: Intent) -> None:
        if isinstance(intent, WatchPtz):
            self.watch(intent.on)
        elif isinstance(intent, PtzMove) and intent.relative:
            self.move_rel(intent.pan, intent.tilt, intent.zoom)
        elif isinstance(intent, PtzMove):
            self.move_abs(intent.pan, intent.tilt, intent.zoom)

    def watch(self, on: bool) -> None:
        """Poll the position while ``on`` (the camera page is shown)."""
        self.watching = on
        self._sync()

    async def refresh(self) -> tuple[float, float, float] | None:
        """Read the position once (after login, and while a move is followed); the reading."""
        client, name = self._client, self._name("getCameraData")
        if client is None or not name:
            return None
        with contextlib.suppress(ClientError, ProtocolError):
            reply = await client.request_once(name, timeout=self._timeout)
            self._on_data(Packet(name, reply.payload, reply.received_at))
        return self._state.position

    def _sync(self) -> None:
        client, name = self._client, self._name("getCameraData")
        if client is None or not client.connected or not name:
            return
        if self.watching and not self._polling:
            self._polling = True
            client.request(name, POLL_MS, self._on_data)
        elif not self.watching and self._polling:
            self._polling = False
            client.stop_request(name)

    def _on_data(self, packet: Packet) -> None:
        try:
            data = CameraData.decode(packet.payload)
        except ProtocolError:
            return
        if _finite(data.pan, data.tilt, data.zoom):
            position = (data.pan, data.tilt, data.zoom)
            if position != self._state.position:
                self._set(replace(self._state, position=position))

    # -- moving the head ---------------------------------------------------------------------
    def move_rel(self, pan: float, tilt: float, zoom: float | None = None) -> None:
        """Turn the head by (pan, tilt) degrees and zoom by ``zoom`` points of its range."""
        client, name = self._require("setCameraRel")
        client.send(name, SetCameraRel(_bound(pan), _bound(tilt), None if zoom is None else _bound(zoom)))
        self._after_move(None)

    def move_abs(self, pan: float, tilt: float, zoom: float | None = None) -> None:
        """Point the head at (pan, tilt) degrees, zoom % (None: keep the zoom as it is)."""
        client, name = self._require("setCameraAbs")
        if zoom is None:
            position = self._state.position
            zoom = position[2] if position is not None else 0.0  # ARIA reads a missing zoom as 0
        client.send(name, SetCameraAbs(_bound(pan), _bound(tilt), _bound(zoom)))
        self._after_move(self._clamped(pan, tilt, zoom))

    def _clamped(self, pan: float, tilt: float, zoom: float) -> tuple[float, float, float] | None:
        s = self._state
        if s.pan_range == s.tilt_range == (0.0, 0.0):
            return None  # limits unknown: where it stops is the server's to say

        def within(value: float, limits: tuple[float, float]) -> float:
            return min(max(value, limits[0]), limits[1])

        zoom = within(zoom, s.zoom_range) if s.zoom_available else 0.0
        return (within(pan, s.pan_range), within(tilt, s.tilt_range), zoom)

    def _after_move(self, goal: tuple[float, float, float] | None) -> None:
        """The head is moving: say so at once, and read it until it settles, polled or not (the
        camera page's label follows the key press, and never shows a reading taken mid-turn as
        where the head stopped)."""
        self._move_no += 1
        self._set(replace(self._state, moving=True, goal=goal))
        self.ctx.spawn(self._follow(self._move_no, self._state.position), "ptz-follow")

    async def wait_settled(self) -> None:
        """Until the last move has settled (``rtmu ptz`` prints where the head stopped), bounded."""
        deadline = time.monotonic() + FOLLOW_LIMIT_S + 2 * self._timeout
        while self._state.moving and time.monotonic() < deadline:
            await asyncio.sleep(POLL_MS / 4000)

    async def _follow(self, move_no: int, before: tuple[float, float, float] | None) -> None:
        """Read the position every ``POLL_MS`` until two readings in a row agree and the head could
        have turned that far at :data:`HEAD_SPEEDS`; then the reading is where it stopped."""
        started, last = time.monotonic(), None
        while move_no == self._move_no:
            position = await self.refresh()
            if move_no != self._move_no:
                return  # a newer move (or a new connection) follows its own
            elapsed = time.monotonic() - started
            if position is not None and position == last and elapsed >= turn_time(before, position):
                break
            if position is None or elapsed >= FOLLOW_LIMIT_S:
                break
            last = position
            await asyncio.sleep(POLL_MS / 1000)
        if move_no == self._move_no:
            self._set(replace(self._state, moving=False, goal=None))

    def _require(self, command: str) -> tuple[AriaClient, str]:
        client, name = self._client, self._name(command)
        if client is None or not client.connected:
            raise NotSupported("not connected")
        if not name:
            raise NotSupported(self._state.reason or f"this camera has no {command}")
        return client, name

    def _offers(self, command: str) -> bool:
        return bool(self._name(command))

    def _name(self, command: str) -> str | None:
        cam, client = self._camera, self._client
        if cam is None or client is None:
            return None
        name = cam.data_name(command)
        return name if name and client.supports(name) else None


def turn_time(a: tuple[float, float, float] | None, b: tuple[float, float, float] | None) -> float:
    """Seconds a head at :data:`HEAD_SPEEDS` needs from ``a`` to ``b`` (0 when either is unknown)."""
    if a is None or b is None:
        return 0.0
    return max(abs(x - y) / speed for x, y, speed in zip(a, b, HEAD_SPEEDS, strict=True))


def _bound(value: float) -> float:
    """A finite angle that fits a ``byte2`` hundredth."""
    if not math.isfinite(value):
        return 0.0
    return max(-LIMIT, min(LIMIT, value))

"""What RTMU knows about the robot and the link: plain values that announce real changes.

The model is the single source of truth the window draws from. It never
imports GTK or asyncio and is confined to ONE thread (the UI thread): the
network side hands values over through the runner's "post to UI" function, and
the controller and view read and write the model only from that thread.

Every part is an observable holding one frozen value. ``set(new)`` replaces the
value and calls the observers **only if the value really changed** — the
lesson of the original RTMU thesis, where an unchanged status still cost a
full redraw at every 200 ms update. Timestamps are kept on the values but are
declared ``compare=False``, so a fresh-but-identical status refreshes the
timestamps without waking anybody.

Parts (all on :class:`Model`):

* ``robot``      — :class:`RobotState`: pose, velocities, battery, temperature, status, mode,
  safe drive, Wi-Fi, sonar, timestamps.
* ``map``        — :class:`MapModel`: the downloaded map (``rtmu.maps.MapData``) or why there is none.
* ``camera``     — :class:`CameraImage` (or None): the last picture.
* ``connection`` — :class:`ConnectionState`: phase, server, the data names it offers, the last error.
* ``health``     — :class:`LinkHealth`: RTT, status age, dropped packets, OK/STALE/LOST.
* ``speed``      — :class:`SpeedSetting`: the drive throttle, 10 %…100 % in 10 % steps.
* ``view``       — :class:`ViewOptions`: map zoom and other per-profile view choices.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import Enum
from typing import Any, Generic, TypeVar

T = TypeVar("T")

Observer = Callable[[T, T], None]
"""Called as ``observer(old, new)`` after a real change."""


class Observable(Generic[T]):
    """One value and the observers that want to hear when it really changes.

    Not thread-safe on purpose: the model lives on the UI thread (see module notes).
    An observer that raises does not stop the others; the first error is re-raised
    after all observers ran, so a broken redraw is loud but cannot hide a change.
    """

    __slots__ = ("_observers", "_value")

    def __init__(self, value: T) -> None:
        self._value = value
        self._observers: list[Callable[[T, T], None]] = []

    @property
    def value(self) -> T:
        return self._value

    def observe(self, observer: Callable[[T, T], None]) -> Callable[[], None]:
        """Add an observer; returns a function that removes it again."""
        self._observers.append(observer)

        def remove() -> None:
            if observer in self._observers:
                self._observers.remove(observer)

        return remove

    def set(self, new: T) -> bool:
        """Store ``new``; notify observers and return True only if it differs from the old value.

        An equal value is still stored, so fields declared ``compare=False``
        (timestamps) stay fresh without costing a notification.
        """
        old = self._value
        self._value = new
        if old == new:
            return False
        error: BaseException | None = None
        for observer in list(self._observers):
            try:
                observer(old, new)
            except Exception as exc:  # one bad observer must not starve the others
                error = error or exc
        if error is not None:
            raise error
        return True

    def update(self, **changes: Any) -> bool:
        """``set(dataclasses.replace(value, **changes))`` for dataclass values."""
        return self.set(dataclasses.replace(self._value, **changes))  # type: ignore[type-var]


# -- robot ---------------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class RobotState:
    """The robot as the server last described it. ``None`` = not reported (yet)."""

    x: float = 0.0
    """mm, map frame."""
    y: float = 0.0
    """mm."""
    th: float = 0.0
    """degrees, counter-clockwise positive, −179…180."""
    vel: float = 0.0
    """mm/s."""
    rot_vel: float = 0.0
    """deg/s."""
    lat_vel: float = 0.0
    """mm/s (0 on non-holonomic robots)."""
    battery_v: float | None = None
    """Volts, or state of charge in % when ``battery_is_soc``."""
    battery_low: float | None = None
    """Low-battery level in the same unit as ``battery_v`` (``batteryInfo``)."""
    battery_shutdown: float | None = None
    """Level at which the robot shuts down."""
    battery_is_soc: bool = False
    temperature: float | None = None
    """°C; None when the server says unknown (−128)."""
    status: str = ""
    """e.g. ``Stopped``, ``Driving`` (``updateStrings``)."""
    mode: str = ""
    """Display mode string, e.g. ``Stop``, ``Drive``, ``UNSAFE Drive``."""
    extended_status: str = ""
    mode_name: str = ""
    """Internal mode name from ``getModeInfo`` (``stop``, ``ratioDrive``…)."""
    safe_drive: bool | None = None
    wifi_quality: int | None = None
    """Link quality as the server publishes it (a ``getStrings`` item); None if not offered."""
    wifi_signal: int | None = None
    """Signal level (dBm on Linux) from a ``getStrings`` item; None if not offered."""
    sonar: tuple[tuple[int, int], ...] = ()
    """Current sonar readings, global mm."""
    numbers_at: float | None = field(default=None, compare=False)
    """Monotonic time of the last pose/velocity/battery update (not compared: no redraw)."""
    strings_at: float | None = field(default=None, compare=False)
    """Monotonic time of the last status/mode update."""
    sonar_at: float | None = field(default=None, compare=False)
    laser: tuple[tuple[int, int], ...] = ()
    """Current laser points of every listed ``Laser_*Current`` (LD robots), global mm."""
    laser_at: float | None = field(default=None, compare=False)
    dock_state: str | None = None
    """``Undocked``, ``Docking``, ``Docked``, ``Undocking`` (``dockInfo``); None if not offered."""
    routes: tuple[str, ...] = ()
    """Route names (``getRoutes``, LD robots)."""
    data_store: tuple[tuple[str, str], ...] = ()
    """(data name, value) of every listed ``DataStore_*`` string, sorted by name."""
    goals: tuple[str, ...] = ()
    """The map's goal names (``getGoals``), asked for where ``gotoRouteGoal`` is listed (LD robots)."""
    loc_score: int | None = None
    """Localization score 0–100 from ``DataStore_Localization_Score``; None if not offered."""
    goal_distance_mm: int | None = None
    """Distance left to the goal from ``DataStore_Distance_To_Goal`` (0: no goal); None if not offered."""
    closest_obstacle_mm: int | None = None
    """``DataStore_Closest_Obstacle``; None if not offered or nothing in range."""

    @property
    def battery_pct(self) -> float | None:
        """State of charge in %, when ``batteryInfo`` says the robot reports it; None when volts."""
        return self.battery_v if self.battery_is_soc else None

    @property
    def battery_state(self) -> str:
        """``ok``, ``low``, ``critical`` (at or under the shutdown level) or ``unknown``."""
        if self.battery_v is None:
            return "unknown"
        if self.battery_shutdown is not None and self.battery_v <= self.battery_shutdown:
            return "critical"
        if self.battery_low is not None and self.battery_v <= self.battery_low:
            return "low"
        return "ok"

    @property
    def moving(self) -> bool:
        return self.vel != 0 or self.rot_vel != 0 or self.lat_vel != 0


# -- map -----------------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class MapModel:
    """The server's map and the state of its download.

    ``data`` is an ``rtmu.maps.MapData`` (typed ``object`` here so the model does
    not import numpy-heavy code); ``None`` with ``state == "none"`` means the
    server has no map, which the view shows as the robot alone (thesis §5.8.4).
    """

    state: str = "unknown"
    """``unknown`` (not asked), ``loading``, ``ready``, ``none`` (server has no map), ``failed``,
    ``unsupported`` (server offers no map data)."""
    data: object | None = field(default=None, compare=False)
    name: str = ""
    """The server's map file name (``getMapName``), may be empty."""
    generation: int = 0
    """Bumped for every newly loaded map, so observers see a change even when the name is equal."""
    received: int = 0
    """Packets received so far while loading (progress)."""
    error: str = ""


# -- camera --------------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class CameraImage:
    """One JPEG picture from the robot's camera. The view decodes it; the model only keeps bytes."""

    jpeg: bytes = field(repr=False)
    width: int
    height: int
    source: str
    """Data name it came from (``getPictureCam1``, ``sendVideo``…)."""
    received_at: float = field(compare=False)
    sequence: int = 0
    """Increases for every picture, so two identical frames still count as a new picture."""


# -- connection and link -------------------------------------------------------------------------


class Phase(Enum):
    DISCONNECTED = "disconnected"
    CONNECTING = "connecting"
    CONNECTED = "connected"
    RECONNECTING = "reconnecting"
    FAILED = "failed"
    """The last attempt failed and no retry is planned (``error`` says why)."""


@dataclass(frozen=True, slots=True)
class ConnectionState:
    phase: Phase = Phase.DISCONNECTED
    host: str = ""
    port: int = 0
    user: str = ""
    profile: str = ""
    offers: frozenset[str] = frozenset()
    """Data names the server offers to this user (empty until connected)."""
    error: str = ""
    """An operator-readable sentence for the last failure, or ""."""
    error_kind: str = ""
    """The error's class: ``refused``, ``timeout``, ``login``, ``closed``, ``protocol``, ``unsupported``…"""
    attempt: int = 0
    """Reconnect attempt number while RECONNECTING."""
    retry_in: float | None = None
    """Seconds until the next reconnect attempt, if one is planned."""

    @property
    def connected(self) -> bool:
        return self.phase is Phase.CONNECTED

    def supports(self, name: str) -> bool:
        return name in self.offers


class LinkLevel(Enum):
    DOWN = "down"
    """Not connected."""
    OK = "ok"
    STALE = "stale"
    """No status for 3 update intervals, or a ping went unanswered: driving is stopped."""
    LOST = "lost"
    """No status for 2 s, or 3 pings unanswered: the link is considered gone (reconnect if enabled)."""


@dataclass(frozen=True, slots=True)
class LinkHealth:
    level: LinkLevel = LinkLevel.DOWN
    rtt_ms: float | None = None
    """Round-trip time of the last ping, rounded to 0.1 ms; None before the first."""
    dropped: int = 0
    """Packets the decoder threw away (bad length or checksum) on this connection."""
    garbage_bytes: int = 0
    """Bytes skipped while resynchronising."""
    status_age: float | None = field(default=None, compare=False)
    """Seconds since the last status packet (not compared: it changes all the time)."""
    ping_failures: int = 0
    """Pings in a row the server did not answer: it may no longer hear us (RTT is then None)."""


# -- operator settings ---------------------------------------------------------------------------

SPEED_MIN = 10
SPEED_MAX = 100
SPEED_STEP = 10


@dataclass(frozen=True, slots=True)
class SpeedSetting:
    """The drive throttle in percent: 10…100 in steps of 10 (the thesis's +/- keys)."""

    percent: int = 50

    def __post_init__(self) -> None:
        if not SPEED_MIN <= self.percent <= SPEED_MAX or self.percent % SPEED_STEP:
            raise ValueError(f"speed must be {SPEED_MIN}…{SPEED_MAX} in steps of {SPEED_STEP}")

    def faster(self) -> SpeedSetting:
        return SpeedSetting(min(SPEED_MAX, self.percent + SPEED_STEP))

    def slower(self) -> SpeedSetting:
        return SpeedSetting(max(SPEED_MIN, self.percent - SPEED_STEP))

    @property
    def at_max(self) -> bool:
        return self.percent >= SPEED_MAX

    @property
    def at_min(self) -> bool:
        return self.percent <= SPEED_MIN


ZOOM_LEVELS: tuple[float, ...] = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0)
"""Map zoom steps. ``0`` in ``ViewOptions.zoom`` means "fit the whole map"."""


@dataclass(frozen=True, slots=True)
class ViewOptions:
    zoom: float = 0.0
    """Map scale relative to 1 px = 10 mm at 1.0 (the view decides the exact meaning); 0 = fit."""
    follow_robot: bool = True
    show_sonar: bool = True


# -- the whole model -----------------------------------------------------------------------------


class Model:
    """Every observable part of RTMU's state, on the UI thread."""

    def __init__(self) -> None:
        self.robot: Observable[RobotState] = Observable(RobotState())
        self.map: Observable[MapModel] = Observable(MapModel())
        self.camera: Observable[CameraImage | None] = Observable(None)
        self.connection: Observable[ConnectionState] = Observable(ConnectionState())
        self.health: Observable[LinkHealth] = Observable(LinkHealth())
        self.speed: Observable[SpeedSetting] = Observable(SpeedSetting())
        self.view: Observable[ViewOptions] = Observable(ViewOptions())

    def reset_robot(self) -> None:
        """Forget robot, map and picture (after a disconnect: stale values must not look live)."""
        self.robot.set(RobotState())
        self.map.set(MapModel())
        self.camera.set(None)
        self.health.set(LinkHealth())

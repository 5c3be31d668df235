"""The values RTMU knows about one robot and its link, and the typed changes that carry them.

Plain frozen dataclasses: the network thread builds them, hands them over as a
:data:`StateChange` (one class per part, so a change can never land on the
wrong part), and the UI thread keeps them in :class:`rtmu.model.observables.RobotModel`.
Nothing here imports GTK or asyncio, and nothing here is tied to a thread, so
the client layer uses this module and never the UI thread's observables.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum, StrEnum
from typing import TYPE_CHECKING, Protocol

from .commission import ScanState, TransfersState

if TYPE_CHECKING:
    from ..mapfile.model import MapData


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
    mode_locked: bool = False
    """``getModeInfo``: the active mode is locked (no other mode may take over: docking, safety)."""
    mode_will_unlock: bool = False
    """``getModeInfo``: the locked mode gives way when another mode asks (the dock backs out first)."""
    safe_drive: bool | None = None
    wifi_quality: int | None = None
    """Link quality in % (a ``getStrings`` item's 0–70, an LD robot's DataStore item, turned into %);
    None if not offered."""
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
    """Current points of every listed laser (``Laser_1Current``, ``sim_lms2xx_1Current`` …), global mm."""
    laser_at: float | None = field(default=None, compare=False)
    dock_state: str | None = None
    """``Undocked``, ``Docking``, ``Docked``, ``Undocking`` (``dockInfo``); None if not offered."""
    routes: tuple[str, ...] = ()
    """Route names (``getRoutes``, LD robots)."""
    data_store: tuple[tuple[str, str], ...] = ()
    """(data name, value) of every listed ``DataStore_*`` string, sorted by name."""
    closest_obstacle_mm: int | None = None
    """``DataStore_Closest_Obstacle``; None if not offered or nothing in range."""
    server_strings: tuple[tuple[str, str], ...] = ()
    """(label, value) of the server's ``getStrings`` items, only while the details table asks for them."""
    server_strings_more: int = 0
    """Items published beyond what ``server_strings`` keeps (bounded: ``client.server_strings``)."""
    ptz: PtzState | None = None
    """The pan-tilt-zoom camera as the server describes it; None before the camera list is read."""

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

    @property
    def mode_lock(self) -> str:
        """The mode lock in words ("" when unlocked), told to the operator instead of a silent refusal."""
        if not self.mode_locked:
            return ""
        name = self.mode or self.mode_name or "its current"
        if self.mode_will_unlock:
            return f"locked in {name} mode; will unlock if asked"
        return f"locked in {name} mode; will not unlock if asked"


@dataclass(frozen=True, slots=True)
class PtzState:
    """One pan-tilt-zoom camera (``getCameraList`` + ``getCameraInfo<N>`` + ``getCameraData<N>``).

    ``reason`` says why the head cannot be moved (empty when it can); angles in degrees, zoom in %
    of its range, as ArServerHandlerCamera sends them. ``position`` is None until it is first read.
    """

    camera: str = ""
    """The camera's name (the data-name suffix, e.g. ``Cam1``)."""
    display_name: str = ""
    camera_type: str = ""
    reason: str = ""
    can_rel: bool = False
    can_abs: bool = False
    pan_range: tuple[float, float] = (0.0, 0.0)
    tilt_range: tuple[float, float] = (0.0, 0.0)
    zoom_range: tuple[float, float] = (0.0, 0.0)
    zoom_available: bool = False
    position: tuple[float, float, float] | None = None
    """(pan, tilt, zoom) as last read: pan positive to the right, tilt positive up (ARIA's convention)."""
    moving: bool = False
    """A move was asked and the server's reading has not settled yet: ``position`` is not where the
    head will stop."""
    goal: tuple[float, float, float] | None = None
    """Where a moving head was pointed (an absolute move, clamped to the limits); None for a turn by."""

    @property
    def movable(self) -> bool:
        return not self.reason and (self.can_rel or self.can_abs)


# -- map -----------------------------------------------------------------------------------------


class MapPhase(StrEnum):
    """Where the map download stands (a ``StrEnum``: it compares equal to its text)."""

    UNKNOWN = "unknown"
    """Not asked yet."""
    LOADING = "loading"
    READY = "ready"
    NONE = "none"
    """The server has no map: the view shows the robot alone (thesis §5.8.4)."""
    FAILED = "failed"
    UNSUPPORTED = "unsupported"
    """The server offers no map data."""


@dataclass(frozen=True, slots=True)
class MapModel:
    """The server's map and the state of its download (``data`` only when ``state`` is READY)."""

    state: MapPhase = MapPhase.UNKNOWN
    data: MapData | None = field(default=None, compare=False)
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
    stamp_ns: int | None = field(default=None, compare=False)
    """Wall-clock ns the server rendered it (the simulator's ``RTMU-T`` comment); None: not stamped."""
    video: VideoStatus | None = field(default=None, compare=False)
    """Live video's figures when this frame came from the video loop (None: a single picture)."""
    frame: int | None = field(default=None, compare=False)
    """The video loop's own number for this frame (None: a single picture): what the window hands
    back once it has painted it (``VideoShown``), so the loop asks for the next."""


@dataclass(frozen=True, slots=True)
class VideoStatus:
    """What live video's caption shows: rate, traffic, age, and why the rate is lower than asked."""

    fps: float
    kbps: float
    age_ms: float | None
    target_fps: float
    rate_fps: float
    backoff: str
    """Plain words when the rate was lowered because the link is slow ("" at the asked rate)."""
    paused: bool
    dropped: int
    note: str
    """The last dropped frame's reason ("" when none)."""

    def caption(self) -> str:
        """One short line for the picture: "12.0 fps · 310 kB/s · 45 ms old"."""
        from ..base.i18n import _, words
        from ..base.units import quantity

        parts = [quantity(self.fps, "fps", 1), quantity(self.kbps, "kB/s")]
        if self.age_ms is not None:
            parts.append(_("{age} old").format(age=quantity(self.age_ms, "ms")))
        if self.paused:
            parts.append(_("paused"))
        if self.backoff:
            parts.append(words(self.backoff))
        if self.dropped:
            dropped = _("{count} dropped").format(count=self.dropped)
            parts.append(dropped + (_(" (last: {note})").format(note=self.note) if self.note else ""))
        return " · ".join(parts)


# -- navigation ----------------------------------------------------------------------------------


class NavOutcome(StrEnum):
    """Where a navigation stands, read from the server's words: the one enum of the window, the CLI and
    "why won't it move" (a ``StrEnum``: it compares equal to its text).

    As a state's ``outcome``: how the last navigation ended (``NONE`` while none has, or one is under way)."""

    NONE = ""
    """Nothing has ended yet on this connection (or one is under way); as one status read: no news."""
    GOING = "going"
    """One status read: the server is on its way (``Going to …``); never a state's ``outcome``."""
    ARRIVED = "arrived"
    DOCKED = "docked"
    FAILED = "failed"
    CANCELLED = "cancelled"
    """It stopped before arriving: a stop, a drive command or another mode took over."""


@dataclass(frozen=True, slots=True)
class NavState:
    """What an ARNL-class server is doing with the robot on its own: goals, path, localization.

    Read from the mode name and status strings (ARNL's words: ``Going to …``, ``Arrived at …``,
    ``Failed to get to …``, ``Docked``), ``getPath``, ``getLocState`` and ``getGoals`` — each only
    where the server lists it. Defaults mean "not offered or not known".
    """

    offered: frozenset[str] = frozenset()
    """The navigation data the server lists (``gotoGoal``, ``home``, ``dock``, ``getLocState`` …)."""
    navigating: bool = False
    """The server is driving the robot to a goal, a point, home or the dock right now."""
    target: str = ""
    """Where to, in the server's words: a goal name, ``point``, ``home``, ``dock at Charger``."""
    target_pose: tuple[float, float, float | None] | None = None
    """(x mm, y mm, heading ° or None) when known: what we sent, or the map's goal of that name."""
    path: tuple[tuple[int, int], ...] = ()
    """The planned path still ahead (``getPath``, map mm), while navigating."""
    remaining_mm: float | None = None
    """Distance left to the goal: along ``path`` from the robot's pose (ARNL), or an LD robot's own
    ``DataStore_Distance_to_goal``; None without a path or a goal."""
    outcome: NavOutcome = NavOutcome.NONE
    outcome_text: str = ""
    """The server's own sentence for the outcome (``Arrived at Lab B``), bounded."""
    reason: str = ""
    """Why it failed, in plain words (``the robot is lost``, ``path blocked``); "" otherwise."""
    loc_state: str | None = None
    """``Good``, ``Idle``, ``Lost``, ``Initializing`` (``getLocState``); None if not offered."""
    loc_score: float | None = None
    """Localization score 0.0–1.0: ARNL's ``getLocState``, or an LD robot's ``DataStore_…Localization
    Score`` (0–100 on the wire, one scale here); None if not offered."""
    goals: tuple[str, ...] = ()
    """The map's goal names (``getGoals``), refreshed on ``goalsUpdated``."""

    def offers(self, name: str) -> bool:
        return name in self.offered


# -- server popups -------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class PopupInfo:
    """One open server popup (``popupCreate``), its texts already cut to a bounded length."""

    popup_id: int
    title: str
    message: str
    icon: int
    """The wire's popup type: 0 none, 1 information, 2 warning, 3 critical, 4 question."""
    buttons: tuple[str, ...]
    """Three labels; the index is the button number the server expects, "" means no such button."""
    default_button: int = 0
    escape_button: int = 0
    opened_at: float = field(default=0.0, compare=False)
    """Monotonic seconds when it arrived (the card counts from here: the wire carries no timeout)."""


@dataclass(frozen=True, slots=True)
class PopupsState:
    """The server popups open now, oldest first: at most a bounded number, the rest only counted."""

    open: tuple[PopupInfo, ...] = ()
    dropped: int = 0
    """Popups that arrived while the list was full (never shown; a flooding server), less those
    the server has closed since."""
    offered: bool = False
    """The server offers popups (``popupCreate``) at all."""


# -- the server's drawings -----------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class DrawingLayer:
    """One drawing the server listed (``getDrawingList``), as this client shows it, and its last points."""

    name: str
    """The server's own name (its data name): untrusted text, shown literally."""
    shape: str
    """``polyDots``, ``polyArrows``, ``polyLine``, ``polyPoints``, ``polySegments`` or anything else."""
    drawable: bool
    """False for a shape RTMU does not know: listed with a note, never asked for, never drawn."""
    color: int
    """0xRRGGBB."""
    size: int
    layer: int
    refresh_ms: int
    """How often it is asked for while shown (the server's period, at least the client's minimum)."""
    shown: bool
    """On the map now (the server's visibility, or the operator's choice where they may choose)."""
    may_toggle: bool
    """The server lets the operator turn it on and off (``DefaultOn`` / ``DefaultOff``)."""
    points: tuple[tuple[int, int], ...] = ()
    """Global mm, as last received — evenly thinned when the drawings together exceed the window's
    budget (``client.drawing_budget``); empty while hidden."""
    total_points: int = 0
    """How many points the last sample had (more than ``points`` holds when thinned)."""
    problem: str = ""
    """Why its last sample was refused (malformed, too many points), or ""."""


@dataclass(frozen=True, slots=True)
class DrawingsState:
    """The server's drawings, lowest layer first (drawn in this order)."""

    layers: tuple[DrawingLayer, ...] = ()
    offered: bool = False
    """The server lists drawings: then its sonar and lasers are drawn from here, in its colours."""
    note: str = ""
    """Why the list could not be read, or ""."""


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
    server_tag: str = ""
    """The version tag of the server's introduction (what About's debug information quotes)."""
    server_protocol: str = ""
    """The protocol string the server's introduction asked for, as sent (untrusted text)."""
    sent_protocol: str = ""
    """The protocol string this client answered with."""

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
    """No status for longer than the link's learned limit (``base.link_timing``: 0.2–0.45 s), or a
    ping went unanswered: driving is stopped."""
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
    stale_limit: float | None = None
    """Seconds without status after which the link counts as stale, as learned now (0.01 s steps)."""
    jitter_ms: float | None = None
    """How late status came lately above its normal pace (5 ms steps): what the limit was learned from."""
    cause: str = field(default="", compare=False)
    """While not OK: why, measured ("no status for 0.46 s, learned jitter 90 ms …"), with what to do."""


# -- typed changes -------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class RobotChanged:
    value: RobotState


@dataclass(frozen=True, slots=True)
class MapChanged:
    value: MapModel


@dataclass(frozen=True, slots=True)
class CameraChanged:
    value: CameraImage | None


@dataclass(frozen=True, slots=True)
class ConnectionChanged:
    value: ConnectionState


@dataclass(frozen=True, slots=True)
class HealthChanged:
    value: LinkHealth


@dataclass(frozen=True, slots=True)
class NavChanged:
    value: NavState


@dataclass(frozen=True, slots=True)
class PopupsChanged:
    value: PopupsState


@dataclass(frozen=True, slots=True)
class DrawingsChanged:
    value: DrawingsState


@dataclass(frozen=True, slots=True)
class ScanChanged:
    value: ScanState


@dataclass(frozen=True, slots=True)
class TransfersChanged:
    value: TransfersState


StateChange = (
    RobotChanged
    | MapChanged
    | CameraChanged
    | ConnectionChanged
    | HealthChanged
    | NavChanged
    | PopupsChanged
    | DrawingsChanged
    | ScanChanged
    | TransfersChanged
)
"""What the network side publishes: the class says which part changed, the value is the new whole."""


class StateSink(Protocol):
    """Where a runner's changes land, on the UI thread (``RobotModel``; a recorder or a test list)."""

    def apply(self, change: StateChange) -> None: ...

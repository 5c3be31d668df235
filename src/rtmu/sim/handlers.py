"""What the simulator answers for each data name: one small function per data.

A handler gets a :class:`Call` (who asked, for which data, with which
arguments) and returns the replies: payload bytes sent under the data's own
number, :class:`Other` for a packet under another data's number, or
:class:`Stream` for a download already framed (the cached map streams). Every
payload is built with the typed payloads of :mod:`rtmu.protocol.payloads`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from rtmu.protocol.errors import FieldUnderrun, PayloadError
from rtmu.protocol.payloads.commands import CommandEntry, CommandList, StringCommandArgs, StringCommandList
from rtmu.protocol.payloads.drawings import Drawing, DrawingList, DrawingListPacket
from rtmu.protocol.payloads.drive import (
    MoveDist,
    RatioDrive,
    SafeDrive,
    SetSafeDrive,
    TurnByAngle,
    TurnToHeading,
)
from rtmu.protocol.payloads.map import MapWithMaxCategoryRequest
from rtmu.protocol.payloads.popup import PopupClicked, PopupClose, PopupCreate, PopupListEnd
from rtmu.protocol.payloads.robot import (
    ActivityTimeInfo,
    BatteryInfo,
    ModeBusyChanged,
    ModeData,
    ModeDataList,
    ModeInfo,
    PhysicalInfo,
    Update,
    UpdateNumbers,
    UpdateStrings,
)
from rtmu.protocol.payloads.sensors import (
    RangeDeviceReadings,
    SensorCurrentRequest,
    SensorList,
    SensorReadings,
)
from rtmu.protocol.payloads.server import IdleProcessingPending, SelfIdentifier
from rtmu.protocol.payloads.strings import StringItem, Strings, StringsInfo

from . import laser, p3dx
from .catalogue import STRING_COMMANDS, Row
from .robot import normalize_deg

if TYPE_CHECKING:
    from .context import SimClient, SimHost
    from .world import Popup, World

TEMPERATURE_MOBILESIM = -127
"""What MobileSim reports for the robot's temperature (captured)."""
SENSORS = (laser.NAME, "sonar")
"""Range devices in ARIA's order (as serverDemo with MobileSim lists them: the laser first)."""
SONAR_DRAWING = Drawing("sonarCurrent", "polyArrows", 0x0033CCFF, 200, 70, 200, 0x000000, "DefaultOn")
"""ARIA's sonar drawing: light-blue arrows 200 mm long, layer 70, asked for every 200 ms."""
LASER_DRAWING = Drawing(f"{laser.NAME}Current", "polyDots", 0x000000FF, 80, 75, 200, 0x000000, "DefaultOn")
"""ARIA's laser drawing: blue dots 80 mm across, layer 75 (above the sonar)."""
DRAWINGS = (LASER_DRAWING, SONAR_DRAWING)
"""What getDrawingList lists, sorted by name as ARIA's case-insensitive map keeps them."""


@dataclass(frozen=True, slots=True)
class Other:
    """A reply packet under another data's number (``popupList`` re-sends ``popupCreate``s)."""

    name: str
    payload: bytes


@dataclass(frozen=True, slots=True)
class Stream:
    """A download: packets already framed with this data's number, in chunks of whole packets.

    The server sends it as the client reads, one download per client at a time (see ``SimClient.stream``).
    """

    chunks: tuple[bytes, ...]


Reply = bytes | Other | Stream


@dataclass(slots=True)
class Call:
    server: SimHost
    session: SimClient
    name: str
    number: int
    args: bytes
    once: bool
    """A request-once (or the first reply to a new subscription); False for periodic invocations."""

    @property
    def world(self) -> World:
        return self.server.world


Handler = Callable[[Call], Iterable[Reply]]
HANDLERS: dict[str, Handler] = {}
BROADCAST_ONLY = frozenset(
    {
        "mapUpdated",
        "goalsUpdated",
        "requestClientRestart",
        "popupCreate",
        "popupClose",
        "cameraListUpdated",
        "cameraParamUpdated",
        "configUpdated",
    }
)
"""Data whose ARIA handler is empty: a subscription gets no immediate reply, only broadcasts."""


def handles_into(table: dict[str, Handler]) -> Callable[..., Callable[[Handler], Handler]]:
    """A ``@handles(name, …)`` decorator that registers into ``table`` (each data module keeps its own)."""

    def handles(*names: str) -> Callable[[Handler], Handler]:
        def register(fn: Handler) -> Handler:
            for n in names:
                table[n] = fn
            return fn

        return register

    return handles


handles = handles_into(HANDLERS)


def decode_lenient(cls, args: bytes):
    """Decode arguments as ARIA reads them: missing trailing fields count as 0 / "" (§1.5)."""
    try:
        return cls.decode(args)
    except (FieldUnderrun, PayloadError, ValueError):
        return cls.decode(args + b"\x00" * 8)


# -- nothing to say -------------------------------------------------------------------
@handles("identSetSelfIdentifier")
def _self_identifier(call: Call) -> Iterable[Reply]:
    """Remembered per client, so tests can tell who sent a ``stop`` (``SimServer.stop_log``)."""
    call.session.self_identifier = decode_lenient(SelfIdentifier, call.args).identifier
    return ()


@handles(
    "identSetHereGoal",
    "requestOnceReturnIsAlwaysTcp",
    "startRequestTransaction",
    "endRequestTransaction",
)
def _silent(call: Call) -> Iterable[Reply]:
    return ()


@handles("idleProcessingPending")
def _idle_pending(call: Call) -> Iterable[Reply]:
    return (IdleProcessingPending(False).encode(),)


# -- robot status -----------------------------------------------------------------------
def numbers(call: Call) -> UpdateNumbers:
    b = call.world.body
    th = round(normalize_deg(b.th))
    if th == -180:
        th = 180
    return UpdateNumbers(
        battery=b.battery_v,
        x=int(b.x),
        y=int(b.y),
        th=th,
        vel=int(b.vel),
        rot_vel=int(b.rot_vel),
        lat_vel=0,
        temperature=TEMPERATURE_MOBILESIM,
    )


@handles("updateNumbers")
def _update_numbers(call: Call) -> Iterable[Reply]:
    return (call.server.cycle_cached("updateNumbers", lambda: numbers(call).encode()),)


def strings_payload(world: World) -> bytes:
    return UpdateStrings(*world.strings()).encode()


def mode_info_payload(world: World) -> bytes:
    return ModeInfo(*world.mode_info()).encode()


@handles("updateStrings")
def _update_strings(call: Call) -> Iterable[Reply]:
    return (strings_payload(call.world),)


@handles("update")
def _update(call: Call) -> Iterable[Reply]:
    status, mode, _ = call.world.strings()
    return (Update(status, mode, numbers(call)).encode(),)


@handles("batteryInfo")
def _battery_info(call: Call) -> Iterable[Reply]:
    return (BatteryInfo(p3dx.BATTERY_LOW_V, p3dx.BATTERY_SHUTDOWN_V, False).encode(),)


@handles("physicalInfo")
def _physical_info(call: Call) -> Iterable[Reply]:
    info = PhysicalInfo(
        p3dx.ROBOT_TYPE, p3dx.ROBOT_SUBTYPE, p3dx.WIDTH_MM, p3dx.LENGTH_FRONT_MM, p3dx.LENGTH_REAR_MM, False
    )
    return (info.encode(),)


@handles("activityTimeInfo")
def _activity_time(call: Call) -> Iterable[Reply]:
    return (ActivityTimeInfo(int(call.world.seconds_since_activity())).encode(),)


# -- modes -------------------------------------------------------------------------------
@handles("getModeInfo")
def _mode_info(call: Call) -> Iterable[Reply]:
    return (mode_info_payload(call.world),)


@handles("getModeDataList")
def _mode_data_list(call: Call) -> Iterable[Reply]:
    rows = sorted((m.NAME, d) for m in call.world.modes for d in m.DATA)
    return (ModeDataList(tuple(ModeData(m, d) for m, d in rows)).encode(),)


@handles("modeBusyChanged")
def _mode_busy(call: Call) -> Iterable[Reply]:
    return (ModeBusyChanged(call.world.seconds_since_activity() < 1.0).encode(),)


# -- driving -----------------------------------------------------------------------------
@handles("stop")
def _stop(call: Call) -> Iterable[Reply]:
    call.server.stop_log.append((call.world.time, call.session.ident, call.session.self_identifier))
    call.world.stop()
    return ()


@handles("ratioDrive")
def _ratio_drive(call: Call) -> Iterable[Reply]:
    r = decode_lenient(RatioDrive, call.args)
    world = call.world
    if not world.ratio_mode.safe and not call.session.may_use("UnsafeMovement"):
        world.set_safe_drive(True)
    world.ratio_drive(_finite(r.trans), _finite(r.rot), _finite(r.throttle), _finite(r.lat_ratio))
    return ()


@handles("setSafeDrive")
def _set_safe_drive(call: Call) -> Iterable[Reply]:
    call.world.set_safe_drive(decode_lenient(SetSafeDrive, call.args).safe)
    return ()


@handles("safeRatioDrivingEnable")
def _safe_on(call: Call) -> Iterable[Reply]:
    call.world.set_safe_drive(True)
    return ()


@handles("safeRatioDrivingDisable")
def _safe_off(call: Call) -> Iterable[Reply]:
    call.world.set_safe_drive(False)
    return ()


@handles("getSafeDrive")
def _get_safe_drive(call: Call) -> Iterable[Reply]:
    return (SafeDrive(call.world.ratio_mode.safe).encode(),)


@handles("wander")
def _wander(call: Call) -> Iterable[Reply]:
    call.world.wander()
    return ()


@handles("moveDist")
def _move_dist(call: Call) -> Iterable[Reply]:
    call.world.move_distance(_finite(decode_lenient(MoveDist, call.args).distance))
    return ()


@handles("turnByAngle")
def _turn_by(call: Call) -> Iterable[Reply]:
    call.world.turn_by(_finite(decode_lenient(TurnByAngle, call.args).angle))
    return ()


@handles("turnToHeading")
def _turn_to(call: Call) -> Iterable[Reply]:
    call.world.turn_to(_finite(decode_lenient(TurnToHeading, call.args).heading))
    return ()


def _finite(value: float) -> float:
    return value if math.isfinite(value) else 0.0


# -- sensors -----------------------------------------------------------------------------
@handles("getSensorList")
def _sensor_list(call: Call) -> Iterable[Reply]:
    return (SensorList(SENSORS).encode(),)


@handles("getSensorCurrent", "getSensorCumulative")
def _sensor_current(call: Call) -> Iterable[Reply]:
    try:
        names = SensorCurrentRequest.decode(call.args).names
    except (FieldUnderrun, PayloadError, ValueError):
        names = ()
    out: list[Reply] = []
    for name in names[:64]:
        if name == "sonar":
            out.append(SensorReadings(name, tuple(call.world.sonar())).encode())
        elif name == laser.NAME:
            out.append(SensorReadings(name, tuple(call.world.laser())).encode())
        else:
            out.append(SensorReadings(name, (), exists=False).encode())
    return out


@handles("sonarCurrent")
def _sonar_current(call: Call) -> Iterable[Reply]:
    return (
        call.server.cycle_cached(
            "sonarCurrent", lambda: RangeDeviceReadings(tuple(call.world.sonar())).encode()
        ),
    )


@handles(LASER_DRAWING.name)
def _laser_current(call: Call) -> Iterable[Reply]:
    return (
        call.server.cycle_cached(
            LASER_DRAWING.name, lambda: RangeDeviceReadings(tuple(call.world.laser())).encode()
        ),
    )


@handles("getDrawingList")
def _drawing_list(call: Call) -> Iterable[Reply]:
    return (*(DrawingListPacket(d).encode() for d in DRAWINGS), DrawingListPacket(None).encode())


@handles("listDrawings")
def _list_drawings(call: Call) -> Iterable[Reply]:
    return (DrawingList(DRAWINGS).encode(),)


# -- map ----------------------------------------------------------------------------------
@handles("getMapName")
def _map_name(call: Call) -> Iterable[Reply]:
    return (call.server.map.name_payload(),)


@handles("getMapId")
def _map_id(call: Call) -> Iterable[Reply]:
    return (call.server.map.id_payload(),)


@handles("getMap")
def _get_map(call: Call) -> Iterable[Reply]:
    return (Stream(call.server.map.text_stream(call.number)),)


@handles("getMapBinary")
def _get_map_binary(call: Call) -> Iterable[Reply]:
    return (Stream(call.server.map.binary_stream(call.number)),)


@handles("getMapMultiScans")
def _get_map_multi(call: Call) -> Iterable[Reply]:
    return (Stream(call.server.map.binary_stream(call.number, "2D-Map-Ex")),)


@handles("getMapWithMaxCategory")
def _get_map_category(call: Call) -> Iterable[Reply]:
    category = decode_lenient(MapWithMaxCategoryRequest, call.args).category
    first = (
        None
        if category.lower() in ("", "2d-map")
        else category
        if category in ("2D-Map-Ex", "2D-Map-Ex2")
        else "2D-Map-Ex2"
    )
    return (Stream(call.server.map.binary_stream(call.number, first)),)


@handles("checkMap")
def _check_map(call: Call) -> Iterable[Reply]:
    call.server.check_map()
    return ()


@handles("getGoals")
def _goals(call: Call) -> Iterable[Reply]:
    return (call.server.map.goals_payload(),)


# -- strings (Wi-Fi, CPU, odometry) ----------------------------------------------------------
STRING_ITEMS = (
    ("Motor Packet Count", 10),
    ("CPU Use", 10),
    ("Wireless Link Quality", 9),
    ("Wireless Link Noise", 9),
    ("Wireless Link Signal", 9),
    ("Distance Travelled (m)", 20),
    ("Run time (min)", 20),
)


def string_values(server: SimHost) -> tuple[str, ...]:
    world = server.world
    link = world.wifi()
    return (
        "10",  # MobileSim sends ten motor packets a second
        "% 4.0f%%" % server.cpu.percent,  # noqa: UP031 -- ARIA's own format
        "%d" % link.quality,  # noqa: UP031
        "%d" % link.noise_dbm,  # noqa: UP031
        "%d" % link.signal_dbm,  # noqa: UP031
        "%.2f" % (world.body.odometer_mm / 1000.0),
        "%.2f" % (world.time / 60.0),
    )


@handles("getStringsInfo")
def _strings_info(call: Call) -> Iterable[Reply]:
    return (StringsInfo(tuple(StringItem(label, width) for label, width in STRING_ITEMS)).encode(),)


@handles("getStrings")
def _strings(call: Call) -> Iterable[Reply]:
    return (call.server.cycle_cached("getStrings", lambda: Strings(string_values(call.server)).encode()),)


# -- simple commands ------------------------------------------------------------------------
@handles("listCommands")
def _list_commands(call: Call) -> Iterable[Reply]:
    rows = [r for r in _may_run(call) if r[0] not in STRING_COMMANDS]
    return (CommandList(tuple(CommandEntry(r[0], r[1]) for r in rows)).encode(),)


@handles("listStringCommands")
def _list_string_commands(call: Call) -> Iterable[Reply]:
    rows = [r for r in _may_run(call) if r[0] in STRING_COMMANDS]
    return (StringCommandList(tuple(CommandEntry(r[0], r[1]) for r in rows)).encode(),)


def _may_run(call: Call) -> list[Row]:
    """The commands this client's user may run: ARIA's lists name them all, we list by group."""
    return [r for r in call.server.custom_commands() if call.session.may_use(r[4])]


@handles("SimulatorPopup")
def _popup_command(call: Call) -> Iterable[Reply]:
    text = decode_lenient(StringCommandArgs, call.args).argument
    parts = text.split("|")
    title = parts[0] if parts else ""
    message = parts[1] if len(parts) > 1 else ""
    labels = tuple(b.strip() for b in parts[2].split(",")) if len(parts) > 2 and parts[2].strip() else ("OK",)
    try:
        timeout = float(parts[3]) if len(parts) > 3 else 0.0
    except ValueError:
        timeout = 0.0
    timeout = timeout if math.isfinite(timeout) and 0 <= timeout <= 3600 else 0.0
    buttons = (*labels, "", "", "")[:3]
    kind = 4 if len(labels) > 1 else 1
    call.world.create_popup(title, message, kind=kind, buttons=buttons, timeout=timeout)
    return ()


@handles("SimulatorPopupFlood")
def _popup_flood(call: Call) -> Iterable[Reply]:
    words = decode_lenient(StringCommandArgs, call.args).argument.split()
    try:
        rate, seconds = float(words[0]), float(words[1])
    except (ValueError, IndexError):
        return ()
    if math.isfinite(rate) and math.isfinite(seconds):
        call.world.flood_popups(min(rate, 5000.0), min(seconds, 60.0))
    return ()


@handles("ResetTripOdometer")
def _reset_odometer(call: Call) -> Iterable[Reply]:
    call.world.body.odometer_mm = 0.0
    return ()


@handles("SimulatorResetPose")
def _reset_pose(call: Call) -> Iterable[Reply]:
    call.server.reset_pose()
    return ()


@handles("SimulatorLowBattery")
def _low_battery(call: Call) -> Iterable[Reply]:
    call.world.body.battery_v = min(call.world.body.battery_v, p3dx.BATTERY_LOW_V - 0.05)
    return ()


@handles("SimulatorRecharge")
def _recharge(call: Call) -> Iterable[Reply]:
    call.world.recharge()
    return ()


@handles("SimulatorSetBattery")
def _set_battery(call: Call) -> Iterable[Reply]:
    words = decode_lenient(StringCommandArgs, call.args).argument.split()
    try:
        volts = float(words[0]) if words else math.nan
    except ValueError:
        volts = math.nan
    if math.isfinite(volts) and 0.0 <= volts <= 30.0:
        call.world.set_battery(volts)
    return ()


@handles("SimulatorVideo320x240", "SimulatorVideo640x480")
def _video_size_command(call: Call) -> Iterable[Reply]:
    call.server.video_size = (640, 480) if call.name.endswith("640x480") else (320, 240)
    return ()


# -- popups ----------------------------------------------------------------------------------
def popup_payload(popup: Popup) -> bytes:
    return PopupCreate(
        popup.id,
        popup.ignore_identifier,
        popup.title,
        popup.message,
        popup.kind,
        popup.buttons,
        popup.default_button,
        popup.escape_button,
    ).encode()


def popup_close_payload(popup_id: int, text: str) -> bytes:
    return PopupClose(popup_id, text).encode()


@handles("popupClicked")
def _popup_clicked(call: Call) -> Iterable[Reply]:
    click = decode_lenient(PopupClicked, call.args)
    call.world.click_popup(click.popup_id, click.button)
    return ()


@handles("popupList")
def _popup_list(call: Call) -> Iterable[Reply]:
    out: list[Reply] = [Other("popupCreate", popup_payload(p)) for p in call.world.popups.values()]
    out.append(PopupListEnd().encode())
    return out

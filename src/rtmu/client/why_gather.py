"""Ask a server, read-only, for everything "why won't it move?" needs (:class:`Facts`).

Every request here is a read: status, mode, safe drive, battery, footprint, range readings, the
configuration's teleop section, docking and localization state, and — on an Omron LD robot — the
safety data on :data:`LD_READS`, each only where the data list names it. Nothing that changes
motion is ever sent (looking never moves the robot). A read that fails or times out becomes a
note in the facts, not an error, so one bad reply still leaves an answer; only a lost connection
ends the gathering.

LD replies have no public layout: :func:`split_fields` reads what a reply carries where that is
safe (NUL-terminated strings, or one integer) and the raw bytes are always kept beside it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from ..base.i18n import N_, Said
from ..protocol.datalist import DataEntry
from ..protocol.payloads.drive import SafeDrive
from ..protocol.payloads.ld import DATA_STORE_PREFIX, DockInfo
from ..protocol.payloads.navigation import LocState
from ..protocol.payloads.robot import ModeInfo, PhysicalInfo
from ..protocol.payloads.sensors import RangeDeviceReadings, SensorList, SensorReadings
from .call_values import Reply
from .config_feed import ServerConfig, fetch_config, offers_config
from .connection import AriaClient
from .errors import ClientError, ServerClosed
from .ld_data import LASER_NAMES
from .robot_status import read_status
from .why_values import (
    ARIA_LIMITER_DEFAULTS,
    Facts,
    Footprint,
    Obstacle,
    OurSide,
    RawValue,
    SafeDriveLimits,
)

LD_READS = (
    "getFaults",
    "safetyStatusEStop",
    "safetyStatusSafetyLaser",
    "queryMotors",
    "getBlockDriving",
    "DataStore_Laser_1_Zone",
)
"""An LD robot's safety data RTMU reads where listed (the ``DockInfo*`` and ``DataStore_*EstopCount``
names too): reads only — ``acknowledgeFault`` and ``enableMotors`` act, and are never sent here."""
MAX_SENSORS = 8
MAX_READINGS = 4000
"""Range readings kept per device (an LD laser sends ~500; ARIA's drawings at most 3 998 points)."""
MAX_FIELDS = 64
MAX_FIELD_CHARS = 200
RAW_MAX_BYTES = 64 << 10
RAW_MAX_PACKETS = 64
MAX_HEX_BYTES = 256
TELEOP_SECTION = "teleop"
"""ARIA's ratio-drive mode puts its Timeout and its limiters' parameters in a section named
"Teleop settings" (serverDemo); RTMU's simulator names it "Teleop". Compared case-insensitively."""


async def gather(client: AriaClient, timeout: float, ours: OurSide | None = None) -> Facts:
    """The facts, read now. Raises only when the connection itself is gone."""
    g = _Gatherer(client, timeout)
    return await g.run(ours or OurSide())


class _Gatherer:
    def __init__(self, client: AriaClient, timeout: float) -> None:
        self.client = client
        self.timeout = timeout
        self.notes: list[str] = []
        self.offers = frozenset(e.name for e in client.datalist)

    async def ask(self, name: str, *, raw: bool = False) -> Reply | None:
        """One read where listed; None (with a note) when it fails. A RETURN_NONE entry is never sent:
        it answers nothing, so it is not a read."""
        entry = self.client.datalist.entry(name)
        if entry is None or "RETURN_NONE" in entry.flag_set:
            return None
        try:
            if raw:
                return await self.client.request_once(
                    name, timeout=self.timeout, max_packets=RAW_MAX_PACKETS, max_bytes=RAW_MAX_BYTES
                )
            return await self.client.request_once(name, timeout=self.timeout)
        except ServerClosed:
            raise
        except ClientError as exc:
            if self.client.closed_error is not None:
                raise self.client.closed_error from None
            self.notes.append(f"{name} could not be read: {exc}")
            return None

    async def typed(self, name: str, cls: type) -> object | None:
        reply = await self.ask(name)
        if reply is None:
            return None
        try:
            value = reply.decode()
        except ClientError as exc:
            self.notes.append(f"{name} did not decode: {exc}")
            return None
        return value if isinstance(value, cls) else None

    async def run(self, ours: OurSide) -> Facts:
        robot = await read_status(lambda name: self.typed(name, object), self.offers)
        info = await self.typed("getModeInfo", ModeInfo)
        safe = await self.typed("getSafeDrive", SafeDrive)
        physical = await self.typed("physicalInfo", PhysicalInfo)
        dock = await self.typed("dockInfo", DockInfo)
        loc = await self.typed("getLocState", LocState)
        config = await self.config()
        pose = (int(robot.x), int(robot.y), int(robot.th)) if robot is not None else None
        sensors, obstacles = await self.obstacles(pose)
        faults, raw = await self.ld_reads()
        return Facts(
            offers=self.offers,
            user=self.client.user,
            status=robot.status if robot is not None else "",
            mode=robot.mode if robot is not None else "",
            extended_status=robot.extended_status if robot is not None else "",
            mode_info=info if isinstance(info, ModeInfo) else None,
            safe_drive=safe.safe if isinstance(safe, SafeDrive) else None,
            battery=robot.battery_v if robot is not None else None,
            battery_shutdown=robot.battery_shutdown if robot is not None else None,
            battery_soc=robot is not None and robot.battery_is_soc,
            vel=robot.vel if robot is not None else None,
            rot_vel=robot.rot_vel if robot is not None else None,
            footprint=(
                Footprint(physical.width, physical.length_front, physical.length_rear)
                if isinstance(physical, PhysicalInfo) and physical.width > 0
                else None
            ),
            obstacles=obstacles,
            sensors=sensors,
            limits=limits_from(config),
            dock_state=dock.state_label if isinstance(dock, DockInfo) else None,
            loc_state=loc.state_label if isinstance(loc, LocState) else None,
            teleop_timeout=_teleop_timeout(config),
            faults=faults,
            raw=raw,
            ours=ours,
            notes=tuple(self.notes),
        )

    async def config(self) -> ServerConfig | None:
        if offers_config(self.client) is None:
            return None
        try:
            return await fetch_config(self.client, self.timeout)
        except ServerClosed:
            raise
        except ClientError as exc:
            self.notes.append(f"the configuration could not be read: {exc}")
            return None

    async def obstacles(
        self, pose: tuple[int, int, int] | None
    ) -> tuple[tuple[str, ...], tuple[Obstacle, ...]]:
        """Every listed range device's current readings, in the robot's frame."""
        if pose is None:
            return (), ()
        readings: list[tuple[str, tuple[tuple[int, int], ...]]] = []
        names = await self.typed("getSensorList", SensorList)
        for name in names.names[:MAX_SENSORS] if isinstance(names, SensorList) else ():
            points = await self._sensor(name)
            if points is not None:
                readings.append((name, points))
        for name in LASER_NAMES:  # an LD robot's lasers, as drawings
            reply = await self.ask(name, raw=True)
            if reply is None:
                continue
            try:
                value = RangeDeviceReadings.decode(reply.payload)
            except (ValueError, ClientError) as exc:
                self.notes.append(f"{name} did not decode: {exc}")
                continue
            readings.append((name.removesuffix("Current"), value.readings))
        x, y, th = pose
        c, s = math.cos(math.radians(th)), math.sin(math.radians(th))
        out: list[Obstacle] = []
        for source, points in readings:
            for px, py in points[:MAX_READINGS]:
                dx, dy = px - x, py - y
                out.append(Obstacle(dx * c + dy * s, -dx * s + dy * c, source))
        return tuple(name for name, _ in readings), tuple(out)

    async def _sensor(self, name: str) -> tuple[tuple[int, int], ...] | None:
        if "getSensorCurrent" not in self.offers:
            return None
        try:
            reply = await self.client.request_once("getSensorCurrent", name, timeout=self.timeout)
            value = reply.decode()
        except ServerClosed:
            raise
        except ClientError as exc:
            if self.client.closed_error is not None:
                raise self.client.closed_error from None
            self.notes.append(f"getSensorCurrent {name!r} could not be read: {exc}")
            return None
        if not isinstance(value, SensorReadings) or not value.exists:
            return None
        return value.readings

    async def ld_reads(self) -> tuple[tuple[str, ...] | None, tuple[RawValue, ...]]:
        faults: tuple[str, ...] | None = None
        raw: list[RawValue] = []
        for entry in ld_entries(self.client.datalist):
            reply = await self.ask(entry.name, raw=True)
            if reply is None:
                if "RETURN_NONE" not in entry.flag_set:
                    raw.append(RawValue(entry.name, entry.return_description, "", note="no reply in time"))
                continue
            data = b"".join(reply.payloads)
            fields = split_fields(data)
            raw.append(RawValue(entry.name, entry.return_description, _hex(data), fields))
            if entry.name == "getFaults" and (fields or not data) and _all_text(data):
                faults = tuple(f for f in fields if f.strip())
        return faults, tuple(raw)


def ld_entries(datalist: Iterable[DataEntry]) -> list[DataEntry]:
    """The LD safety data this server lists, in :data:`LD_READS` order, then ``DockInfo*`` and
    ``DataStore_*EstopCount`` by name."""
    by_name = {e.name: e for e in datalist}
    chosen = [by_name[n] for n in LD_READS if n in by_name]
    extra = sorted(
        n
        for n in by_name
        if n.startswith("DockInfo") or (n.startswith(DATA_STORE_PREFIX) and n.endswith("EstopCount"))
    )
    return chosen + [by_name[n] for n in extra if n not in LD_READS]


def split_fields(data: bytes) -> tuple[str, ...]:
    """What a reply of unknown layout carries, where it can be read safely: NUL-terminated printable
    strings, or one little-endian integer of 1, 2 or 4 bytes; () when neither fits."""
    if not data:
        return ()
    if _all_text(data):
        parts = data.split(b"\x00")[:-1]
        return tuple(p.decode("latin-1")[:MAX_FIELD_CHARS] for p in parts[:MAX_FIELDS])
    if len(data) in (1, 2, 4):
        return (str(int.from_bytes(data, "little", signed=True)),)
    return ()


def _all_text(data: bytes) -> bool:
    if not data.endswith(b"\x00"):
        return not data
    return all(p and p.decode("latin-1").isprintable() for p in data.split(b"\x00")[:-1])


def _hex(data: bytes) -> str:
    shown = data[:MAX_HEX_BYTES].hex(" ")
    return shown + (f" … ({len(data)} bytes)" if len(data) > MAX_HEX_BYTES else "")


def _teleop_params(config: ServerConfig | None) -> dict[str, float]:
    """The teleop section's numeric parameters by lower-case name ({} without a configuration)."""
    out: dict[str, float] = {}
    for section in config.sections if config is not None else ():
        if not section.name.lower().startswith(TELEOP_SECTION):
            continue
        for p in section.params:
            if isinstance(p.value, int | float) and not isinstance(p.value, bool):
                out.setdefault(p.name.lower(), float(p.value))
    return out


def _teleop_timeout(config: ServerConfig | None) -> float | None:
    return _teleop_params(config).get("timeout")


def limits_from(config: ServerConfig | None) -> SafeDriveLimits:
    """Safe drive's distances as the server's configuration lists them (ARIA's limiter parameters
    ``Forward``/``Backward`` + ``Clearance``, ``PaddingAtSlowSpeed``, ``SideClearanceAtSlowSpeed``);
    ARIA's own defaults, said to be such, where it lists none."""
    p = _teleop_params(config)
    if "forwardclearance" not in p and "backwardclearance" not in p:
        return ARIA_LIMITER_DEFAULTS
    front = p.get("forwardclearance", 0.0) + p.get("forwardpaddingatslowspeed", 0.0)
    rear = p.get("backwardclearance", 0.0) + p.get("backwardpaddingatslowspeed", 0.0)
    side = max(p.get("forwardsideclearanceatslowspeed", 0.0), p.get("backwardsideclearanceatslowspeed", 0.0))
    return SafeDriveLimits(
        front,
        rear,
        side,
        Said(
            N_("the server's configuration ({section}: {parameters})"),
            section="Teleop",
            parameters="Clearance + PaddingAtSlowSpeed",
        ),
    )

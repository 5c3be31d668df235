"""Simulator profiles: which kind of ARIA server ``rtmu sim`` pretends to be (``--profile NAME``).

``default`` is serverDemo driving a Pioneer 3-DX. ``aram`` behaves on the wire like an Omron
LD-series robot running ARAM: it enforces the protocol string ``6MTX`` (and advertises it in its
INTRODUCTION), reports the battery as state of charge, serves its map with a ``2D-Map-Ex4`` header
and lists a data catalogue of LD size (about 950 names, a few with descriptions of many KB).

Extension point: a profile names *data modules* (``SimProfile.modules``). Each is an importable
module with two attributes, ``ROWS`` (catalogue rows, :data:`rtmu.sim.catalogue.Row`) and
``HANDLERS`` (data name → handler, the same shape as :data:`rtmu.sim.handlers.HANDLERS`). A profile's
catalogue is the default one, then the modules' rows, then the profile's filler rows; its handlers
are the default ones overridden by the profile's own and then by the modules'.
"""

from __future__ import annotations

import dataclasses
import importlib
from collections.abc import Iterable
from dataclasses import dataclass, field

from rtmu.protocol.datalist import DataList
from rtmu.protocol.payloads.robot import BatteryInfo, Update

from . import p3dx
from .catalogue import Row, build_catalogue
from .handlers import HANDLERS, Call, Handler, Reply, numbers

ARAM_PROTOCOL = "6MTX"
"""What LD robots advertise (older ones ``5MTX``; ``D6MTX`` is also seen)."""
EX4_HEADER = "2D-Map-Ex4"
LD_CATALOGUE_SIZE = 950
"""Real LD lists have 889 and 989 names; the aram profile fills its list up to this many."""


@dataclass(frozen=True)
class SimProfile:
    name: str
    summary: str
    protocol_version: str | None = None
    """Enforced and advertised protocol string (None: none, as ARIA's default)."""
    state_of_charge: bool = False
    """Battery figures are percent of charge (×10 in updateNumbers) instead of volts."""
    map_header: str | None = None
    """First line the map is served with (None: as the file says)."""
    catalogue_size: int = 0
    """Pad the data list with plausible extra names up to this many (0: no padding)."""
    modules: tuple[str, ...] = ()
    """Data modules (``ROWS`` + ``HANDLERS``) this profile serves — the extension point."""
    handlers: dict[str, Handler] = field(default_factory=dict)
    """Handlers of this profile that replace the default ones."""
    robot: str = "Pioneer 3-DX"
    """What the simulated robot is, in words (``rtmu sim`` says it when it starts)."""

    def module_parts(self) -> tuple[list[Row], dict[str, Handler]]:
        rows: list[Row] = []
        handlers: dict[str, Handler] = {}
        for name in self.modules:
            module = importlib.import_module(name)
            rows += list(getattr(module, "ROWS", ()))
            handlers.update(getattr(module, "HANDLERS", {}))
        return rows, handlers

    def catalogue(self, camera: bool) -> DataList:
        base = build_catalogue(camera=camera)
        rows: list[Row] = [
            (e.name, e.description, e.argument_description, e.return_description, e.command_group, e.flags)
            for e in base
        ]
        extra, _ = self.module_parts()
        known = {r[0] for r in rows}
        for r in extra:  # the first module to list a name describes it
            if r[0] not in known:
                known.add(r[0])
                rows.append(r)
        if self.catalogue_size > len(rows):
            rows += filler_rows(self.catalogue_size - len(rows), {r[0] for r in rows})
        return DataList.build(rows)

    def handler_table(self) -> dict[str, Handler]:
        _, extra = self.module_parts()
        return {**HANDLERS, **self.handlers, **extra}


# -- state of charge -----------------------------------------------------------------------------
def percent_of_charge(volts: float) -> float:
    """The simulated battery's volts as a state of charge: shutdown level 0 %, full 100 %."""
    span = p3dx.BATTERY_FULL_V - p3dx.BATTERY_SHUTDOWN_V
    return max(0.0, min(100.0, 100.0 * (volts - p3dx.BATTERY_SHUTDOWN_V) / span))


SOC_LOW_PCT = 20.0
SOC_SHUTDOWN_PCT = 5.0


def _soc_numbers(call: Call) -> Iterable[Reply]:
    def make() -> bytes:
        return dataclasses.replace(
            numbers(call), battery=percent_of_charge(call.world.body.battery_v)
        ).encode()

    return (call.server.cycle_cached("updateNumbers", make),)


def _soc_update(call: Call) -> Iterable[Reply]:
    status, mode, _ = call.world.strings()
    n = dataclasses.replace(numbers(call), battery=percent_of_charge(call.world.body.battery_v))
    return (Update(status, mode, n).encode(),)


def _soc_battery_info(call: Call) -> Iterable[Reply]:
    return (BatteryInfo(SOC_LOW_PCT, SOC_SHUTDOWN_PCT, True).encode(),)


def _ex4_map_binary(call: Call) -> Iterable[Reply]:
    from .handlers import Stream

    return (Stream(call.server.map.binary_stream(call.number, EX4_HEADER)),)


# -- a catalogue of LD size ------------------------------------------------------------------------
_SUBSYSTEMS = (
    ("Arm", "ArmConfig"),
    ("Battery", "RobotInfo"),
    ("Cart", "Cart"),
    ("Charger", "Docking"),
    ("Door", "Facilities"),
    ("Elevator", "Facilities"),
    ("Fleet", "Fleet"),
    ("Gripper", "ArmConfig"),
    ("Io", "IO"),
    ("Job", "Jobs"),
    ("Lidar", "SensorInfo"),
    ("Light", "Facilities"),
    ("Localize", "Localization"),
    ("Mapping", "Map"),
    ("Payload", "Payload"),
    ("Queue", "Jobs"),
    ("Safety", "Safety"),
    ("Sector", "Map"),
    ("Speaker", "Audio"),
    ("Traffic", "Fleet"),
)
_ACTIONS = (
    ("Get", "Reports", "RETURN_SINGLE"),
    ("Set", "Changes", "RETURN_NONE"),
    ("List", "Lists every", "RETURN_UNTIL_EMPTY"),
    ("Reset", "Resets", "RETURN_NONE"),
    ("Status", "Broadcasts the state of", "RETURN_SINGLE"),
    ("Changed", "Broadcast when someone changes", "RETURN_SINGLE"),
    ("Enable", "Switches on", "RETURN_NONE"),
    ("Disable", "Switches off", "RETURN_NONE"),
    ("Info", "Describes", "RETURN_SINGLE"),
    ("Schema", "Describes every parameter of", "RETURN_SINGLE"),
)
_THINGS = ("", "Params", "Limits", "Counters", "History")
LONG_DESCRIPTION_EVERY = 97
"""Every so many filler rows gets a description of many kilobytes (LD lists have 16 KB ones)."""


def _long_text(subject: str, size: int) -> str:
    """A parameter listing in our own words, about ``size`` characters long."""
    parts: list[str] = []
    i = 0
    while sum(len(p) for p in parts) < size:
        parts.append(f"byte4: {subject} parameter {i} (units as configured; 0 keeps the current value); ")
        i += 1
    return "".join(parts)[:size]


def filler_rows(count: int, taken: set[str]) -> list[Row]:
    """``count`` plausible data rows not named in ``taken``, the same every time."""
    rows: list[Row] = []
    index = 0
    for thing in _THINGS:
        for subsystem, group in _SUBSYSTEMS:
            for verb, wording, flags in _ACTIONS:
                if len(rows) >= count:
                    return rows
                name = (
                    f"{verb.lower()}{subsystem}{thing}"
                    if verb != "Changed"
                    else f"{subsystem.lower()}{thing}Changed"
                )
                if name in taken:
                    continue
                taken.add(name)
                subject = f"the {subsystem.lower()}" + (f" {thing.lower()}" if thing else "")
                description = f"{wording} {subject}"
                returns = "none" if flags == "RETURN_NONE" else f"string: {subject} as text"
                if index % LONG_DESCRIPTION_EVERY == LONG_DESCRIPTION_EVERY - 1:
                    returns = _long_text(subject, 16_000)
                args = (
                    "none"
                    if verb in ("Get", "List", "Status", "Changed", "Info", "Schema")
                    else "string: value"
                )
                rows.append((name, description, args, returns, group, flags))
                index += 1
    n = 0
    while len(rows) < count:  # past the combinations: numbered spare slots, still unique
        name = f"customData{n}"
        n += 1
        if name not in taken:
            taken.add(name)
            rows.append((name, "A site-specific data slot", "none", "none", "Custom", "RETURN_NONE"))
    return rows


DEFAULT = SimProfile(
    "default",
    "serverDemo with a simulated Pioneer 3-DX, navigating as ARNL does",
    modules=("rtmu.sim.nav_data", "rtmu.sim.arconfig"),
)
ARAM = SimProfile(
    "aram",
    "an Omron LD robot running ARAM: protocol 6MTX, state of charge, Ex4 map, ~950 data",
    protocol_version=ARAM_PROTOCOL,
    state_of_charge=True,
    map_header=EX4_HEADER,
    catalogue_size=LD_CATALOGUE_SIZE,
    modules=("rtmu.sim.nav_data", "rtmu.sim.ld_data", "rtmu.sim.arconfig"),  # LD docking: dockInfo
    handlers={
        "updateNumbers": _soc_numbers,
        "batteryInfo": _soc_battery_info,
        "update": _soc_update,
        "getMapBinary": _ex4_map_binary,
    },
    robot="Omron LD robot (ARAM)",
)
PROFILES: dict[str, SimProfile] = {p.name: p for p in (DEFAULT, ARAM)}


def get_profile(name: str) -> SimProfile:
    try:
        return PROFILES[name]
    except KeyError:
        raise ValueError(f"no simulator profile {name!r} (known: {', '.join(PROFILES)})") from None

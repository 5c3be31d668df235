"""Simulator profiles: which kind of ARIA server ``rtmu sim`` pretends to be (``--profile NAME``).

``default`` is serverDemo driving a Pioneer 3-DX. ``aram`` behaves on the wire like an Omron
LD-series robot running ARAM: it enforces the protocol string ``6MTX`` (and advertises it in its
INTRODUCTION), reports the battery as state of charge, serves its map with a ``2D-Map-Ex4`` header,
has no ARIA camera, and lists only data that 6MTX robots list (:data:`NOT_LISTED_BY_6MTX` leaves out
the rest of serverDemo's and the simulator's own) — among them LD's configuration data
(``getConfigValues`` …, whose layouts are not public: listed, not answered) instead of ArConfig's.

Extension point: a profile names *data modules* (``SimProfile.modules``). Each is an importable
module with two attributes, ``ROWS`` (catalogue rows, :data:`rtmu.sim.catalogue.Row`) and
``HANDLERS`` (data name → handler, the same shape as :data:`rtmu.sim.handlers.HANDLERS`). A profile's
catalogue is the default one, then the modules' rows, less the names it does not list
(``SimProfile.unlisted``); its handlers are the default ones overridden by the profile's own and then
by the modules'. A module may also have ``PLACE_AFTER`` (data name → the name its row follows), so its
rows keep ARIA's registration order among the default ones (``setConfigParam`` right after
``setConfig``, as serverDemo lists it).
"""

from __future__ import annotations

import dataclasses
import importlib
from collections.abc import Iterable
from dataclasses import dataclass, field

from rtmu.protocol.datalist import DataList
from rtmu.protocol.payloads.robot import BatteryInfo, Update

from . import p3dx
from .camera_data import HANDLERS as CAMERA_HANDLERS
from .catalogue import Row, build_catalogue
from .handlers import HANDLERS, Call, Handler, Reply, numbers

SIMULATOR_HOOK = "Simulator"
"""The prefix of the simulator's own commands (never a real robot's)."""
ARAM_PROTOCOL = "6MTX"
"""What LD robots advertise (older ones ``5MTX``; ``D6MTX`` is also seen)."""
EX4_HEADER = "2D-Map-Ex4"


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
    camera: bool = True
    """False: no ARIA camera, whatever ``SimConfig.camera`` says (its data are not listed)."""
    unlisted: frozenset[str] = frozenset()
    """Names of the default catalogue and the modules that this kind of server does not list."""
    test_hooks: bool = True
    """Whether the simulator's own ``Simulator…`` commands (put it in a state: low battery, a fault, a
    locked mode …) are listed by default; a profile true to a real robot's list leaves them out unless
    asked (``SimConfig.test_hooks``, ``rtmu sim --test-hooks``)."""
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

    def catalogue(self, camera: bool, test_hooks: bool | None = None) -> DataList:
        base = build_catalogue(camera=camera)
        rows: list[Row] = [
            (e.name, e.description, e.argument_description, e.return_description, e.command_group, e.flags)
            for e in base
        ]
        extra, _ = self.module_parts()
        after: dict[str, str] = {}
        for name in self.modules:
            after.update(getattr(importlib.import_module(name), "PLACE_AFTER", {}))
        known = {r[0] for r in rows}
        for r in extra:  # the first module to list a name describes it
            if r[0] not in known:
                known.add(r[0])
                anchor = next((i for i, row in enumerate(rows) if row[0] == after.get(r[0])), None)
                rows.insert(len(rows) if anchor is None else anchor + 1, r)
        hooks = self.test_hooks if test_hooks is None else test_hooks
        return DataList.build(
            r for r in rows if r[0] not in self.unlisted and (hooks or not r[0].startswith(SIMULATOR_HOOK))
        )

    def handler_table(self) -> dict[str, Handler]:
        _, extra = self.module_parts()
        return {**HANDLERS, **CAMERA_HANDLERS, **self.handlers, **extra}


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


# -- what a 6MTX robot does not list ----------------------------------------------------------------
# Compared (names only) with the data list of an LD robot speaking protocol 6MTX that a public,
# BSD-licensed ROS 2 package for Omron LD robots published: CollaborativeRoboticsLab/omron_amr on
# GitHub, whose amr_msgs folder held the robot's 989 data names in April 2026. Every name below is
# one that serverDemo, ARNL or this simulator offers and that list does not have.
NOT_LISTED_BY_6MTX = frozenset(
    {
        # serverDemo's sensors, motion and camera (LD robots have lasers, no ARIA camera)
        "getSensorList", "getSensorCurrent", "getSensorCumulative", "sim_lms2xx_1Current", "sonarCurrent",
        "wander", "moveDist", "turnByAngle", "turnToHeading", "safeRatioDrivingEnable",
        "safeRatioDrivingDisable", "videoSize", "sendVideo", "getPictureCam1", "getCameraDataCam1",
        "getCameraInfoCam1", "setCameraAbsCam1", "setCameraPctCam1", "setCameraRelCam1",
        "getCameraModeListCam1", "cameraModeUpdatedCam1", "setCameraModeCam1", "resetCameraCam1",
        "cameraUpdate", "cameraInfo", "camera", "cameraAbs", "cameraPct",
        "getCameraList", "setCameraParams", "cameraListUpdated", "cameraParamUpdated",
        # ArConfig's editing (6MTX robots list getConfigValues / setConfigValues instead)
        "getConfigBySectionsV4", "getConfigBySectionsV3", "getConfigBySectionsV2", "getConfigBySections",
        "setConfig", "getConfigSectionFlags", "getLastEditablePriority",
        # ARNL's that LD robots do not list
        "home", "tourGoals", "pathPlannerStatus",
        # ARIA's mapping loop tags and ArConfig care that 6MTX robots do not list
        "mappingLoopStart", "mappingLoopEnd", "setConfigParam", "getConfigDefaults", "configDefaultsUpdated",
    }
)  # fmt: skip
"""(``getCameraList`` and its kin are on the 6MTX list, but describe cameras; without one they are left
out too — a subset of what a 6MTX robot lists is still true to it.)"""


COMMISSIONING = (
    "rtmu.sim.files_data",
    "rtmu.sim.mapping_data",
    "rtmu.sim.mapchanges",
    "rtmu.sim.configcare",
)
"""ARIA's file services, scan-to-map, live map changes and configuration care: what
commissioning a robot needs, served by every profile."""
DEFAULT = SimProfile(
    "default",
    "serverDemo with a simulated Pioneer 3-DX, navigating as ARNL does",
    modules=("rtmu.sim.nav_data", "rtmu.sim.arconfig", *COMMISSIONING, "rtmu.sim.why_states"),
)
ARAM = SimProfile(
    "aram",
    "an Omron LD robot running ARAM: protocol 6MTX, state of charge, Ex4 map, only data 6MTX robots list",
    protocol_version=ARAM_PROTOCOL,
    state_of_charge=True,
    map_header=EX4_HEADER,
    camera=False,
    unlisted=NOT_LISTED_BY_6MTX,
    test_hooks=False,
    modules=(
        "rtmu.sim.nav_data",
        "rtmu.sim.ld_data",
        *COMMISSIONING,
        "rtmu.sim.why_states",
        "rtmu.sim.ld_safety",
    ),
    # the LD docking replaces ARNL's
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

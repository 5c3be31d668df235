"""Simple commands that put the simulator in the states an operator must be told about ("why won't it
move?"), so every cause has a test. A data module of the profile extension point (``ROWS`` +
``HANDLERS``, :mod:`rtmu.sim.profiles`); the names and descriptions are the simulator's own.

* the stop mode locked — will not unlock if asked (as ARIA rigs' ``RigLockStopMode``, a docking or
  safety mode), or will (``…Unlockable``: it gives way when another mode asks) — and unlocked again;
* a stalled motor (the drive mode's status then says ``Stalled``, as ARIA's does);
* the e-stop pressed and released, the motors off and on (the status then says ``EStop pressed`` /
  ``Motors disabled``: ARIA's ArServerInfoRobot sends no flags for them, so these are the
  simulator's words);
* a box put just ahead of the robot, inside safe drive's distance, and taken away again.

While the e-stop is pressed or the motors are off or stalled, the motors answer no command
(:attr:`rtmu.sim.robot.Body.holds`). Users without Movement or Stop come from ``--users`` files.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Iterable
from typing import TYPE_CHECKING

import numpy as np

from . import p3dx
from .catalogue import Row
from .handlers import Call, Handler, Reply

if TYPE_CHECKING:
    from .context import SimHost
    from .geometry import Obstacles

BOX_GAP_MM = 40.0
"""How far ahead of the round body's edge ``SimulatorObstacleAhead`` puts its box."""
BOX_HALF_WIDTH_MM = 400.0

_MAPS: weakref.WeakKeyDictionary[SimHost, Obstacles] = weakref.WeakKeyDictionary()
"""The walls before the first box, per server, so ``SimulatorClearObstacles`` can put them back."""


def _lock(will_unlock: bool) -> Handler:
    def handler(call: Call) -> Iterable[Reply]:
        world = call.world
        world.activate(world.stop_mode)  # ARIA locks only the active mode: the stop mode takes over first
        if world.mode is world.stop_mode:
            world.stop_mode.lock(will_unlock)
        world.check_mode_info()  # getModeInfo's broadcast carries the lock flags
        return ()

    return handler


def _unlock(call: Call) -> Iterable[Reply]:
    call.world.stop_mode.unlock()
    call.world.check_mode_info()
    return ()


def _hold(what: str, on: bool) -> Handler:
    def handler(call: Call) -> Iterable[Reply]:
        holds = call.world.body.holds
        if on:
            holds.add(what)
        elif what == "estop":
            holds.discard("estop")
            holds.add("motors")  # a released e-stop leaves the motors off until they are enabled
        elif not (what == "motors" and "estop" in holds):  # no motors while the e-stop is pressed
            holds.discard(what)
            if what == "stall":
                call.world.body.stalled = False
        call.world.check_strings()
        return ()

    return handler


def _box_ahead(call: Call) -> Iterable[Reply]:
    world = call.world
    _MAPS.setdefault(call.server, world.obstacles)
    b = world.body
    th = math.radians(b.th)
    ahead = p3dx.RADIUS_MM + BOX_GAP_MM
    cx, cy = b.x + ahead * math.cos(th), b.y + ahead * math.sin(th)
    dx, dy = -math.sin(th) * BOX_HALF_WIDTH_MM, math.cos(th) * BOX_HALF_WIDTH_MM
    world.add_obstacles(np.array([[cx - dx, cy - dy, cx + dx, cy + dy]]))
    return ()


def _clear_boxes(call: Call) -> Iterable[Reply]:
    walls = _MAPS.pop(call.server, None)
    if walls is not None:
        call.world.replace_obstacles(walls)
    return ()


_COMMANDS: tuple[tuple[str, str, Handler], ...] = (
    (
        "SimulatorLockStopMode",
        "Locks the stop mode; it will not unlock if asked (as a safety mode)",
        _lock(False),
    ),
    (
        "SimulatorLockStopModeUnlockable",
        "Locks the stop mode; it gives way when another mode asks",
        _lock(True),
    ),
    ("SimulatorUnlockMode", "Unlocks the stop mode locked by SimulatorLockStopMode", _unlock),
    (
        "SimulatorStallMotors",
        "Stalls the simulated motors (a blocked wheel) until cleared",
        _hold("stall", True),
    ),
    ("SimulatorClearStall", "Frees the stalled motors", _hold("stall", False)),
    ("SimulatorEStop", "Presses the simulated e-stop: the motors stop answering", _hold("estop", True)),
    (
        "SimulatorEStopRelease",
        "Releases the simulated e-stop (the motors stay off until SimulatorMotorsOn)",
        _hold("estop", False),
    ),
    ("SimulatorMotorsOff", "Disables the simulated motors", _hold("motors", True)),
    ("SimulatorMotorsOn", "Enables the simulated motors again", _hold("motors", False)),
    (
        "SimulatorObstacleAhead",
        "Puts a box just ahead of the robot, inside safe drive's distance",
        _box_ahead,
    ),
    ("SimulatorClearObstacles", "Takes away the boxes SimulatorObstacleAhead put down", _clear_boxes),
)

ROWS: tuple[Row, ...] = tuple(
    (name, text, "none", "none", "CustomCommands", "RETURN_NONE") for name, text, _ in _COMMANDS
)
HANDLERS: dict[str, Handler] = {name: handler for name, _, handler in _COMMANDS}

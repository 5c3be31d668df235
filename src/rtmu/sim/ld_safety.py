"""An Omron LD robot's faults and safety data, for ``rtmu sim --profile aram`` (``ROWS`` + ``HANDLERS``).

LD robots list ``getFaults`` / ``faultsUpdate`` / ``acknowledgeFault``, ``safetyStatusEStop``,
``safetyStatusSafetyLaser``, ``queryMotors`` / ``enableMotors``, ``getBlockDriving`` and
``DataStore_Laser_1_Zone``; their layouts are not public. The simulator serves the names with
layouts of its own, described in its own words in the data list (what a client must read from
there): faults as repeated strings, each state as one ``ubyte``. ``SimulatorFault`` raises a fault
that keeps the motors from answering until it is acknowledged. What was acknowledged and enabled
is kept per server in :func:`safety_state`, so tests can prove nothing was sent without a yes.
"""

from __future__ import annotations

import weakref
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from rtmu.protocol.errors import FieldUnderrun
from rtmu.protocol.fields import FieldReader, FieldWriter
from rtmu.protocol.payloads.ld import DataStoreValue

from .catalogue import Row
from .handlers import Call, Handler, Reply

if TYPE_CHECKING:
    from .context import SimHost

PROTECTIVE_FIELD_MM = 300.0
"""``safetyStatusSafetyLaser`` / ``DataStore_Laser_1_Zone`` say 1 while something is this close ahead."""


@dataclass
class SafetyState:
    faults: list[str] = field(default_factory=list)
    raised: int = 0
    acknowledged: list[str] = field(default_factory=list)
    """Every ``acknowledgeFault`` argument received, in order."""
    enables: int = 0
    """``enableMotors`` requests received."""


_STATES: weakref.WeakKeyDictionary[SimHost, SafetyState] = weakref.WeakKeyDictionary()


def safety_state(server: SimHost) -> SafetyState:
    state = _STATES.get(server)
    if state is None:
        state = _STATES[server] = SafetyState()
    return state


def _faults_payload(state: SafetyState) -> bytes:
    w = FieldWriter()
    for fault in state.faults:
        w.string(fault)
    return w.bytes()


def _faults(call: Call) -> Iterable[Reply]:
    return (_faults_payload(safety_state(call.server)),)


def _changed(call: Call, state: SafetyState) -> None:
    holds = call.world.body.holds
    if state.faults:
        holds.add("fault")
    else:
        holds.discard("fault")
    call.server.broadcast("faultsUpdate", _faults_payload(state))


def _acknowledge(call: Call) -> Iterable[Reply]:
    state = safety_state(call.server)
    try:
        which = FieldReader(call.args).string("fault", default="")
    except FieldUnderrun:
        which = ""
    state.acknowledged.append(which)
    state.faults = [f for f in state.faults if which and f != which]
    _changed(call, state)
    return ()


def _raise_fault(call: Call) -> Iterable[Reply]:
    state = safety_state(call.server)
    state.raised += 1
    state.faults.append(f"Drive fault {state.raised}: simulated motor controller fault")
    _changed(call, state)
    return ()


def _flag(value: bool) -> bytes:
    return FieldWriter().ubyte(1 if value else 0).bytes()


def _near_ahead(call: Call) -> bool:
    return call.world.body.free_distance(True, PROTECTIVE_FIELD_MM) < PROTECTIVE_FIELD_MM


def _enable(call: Call) -> Iterable[Reply]:
    safety_state(call.server).enables += 1
    holds = call.world.body.holds
    if "estop" not in holds:
        holds.discard("motors")
        call.world.check_strings()
    return ()


HANDLERS: dict[str, Handler] = {
    "getFaults": _faults,
    "faultsUpdate": _faults,
    "acknowledgeFault": _acknowledge,
    "safetyStatusEStop": lambda call: (_flag("estop" in call.world.body.holds),),
    "safetyStatusSafetyLaser": lambda call: (_flag(_near_ahead(call)),),
    "queryMotors": lambda call: (_flag(not {"estop", "motors"} & call.world.body.holds),),
    "enableMotors": _enable,
    "getBlockDriving": lambda call: (_flag(bool(call.world.body.holds)),),
    "DataStore_Laser_1_Zone": lambda call: (DataStoreValue("1" if _near_ahead(call) else "0").encode(),),
    "SimulatorFault": _raise_fault,
}

_SAFETY = "Safety"
ROWS: tuple[Row, ...] = (
    (
        "getFaults",
        "The robot's active faults",
        "none",
        "string: fault, repeated (none: no faults)",
        _SAFETY,
        "RETURN_SINGLE",
    ),
    ("faultsUpdate", "Broadcast when the faults change", "none", "as getFaults", _SAFETY, "RETURN_SINGLE"),
    (
        "acknowledgeFault",
        "Acknowledges a fault",
        "string: fault, as getFaults lists it",
        "none",
        _SAFETY,
        "RETURN_NONE",
    ),
    ("safetyStatusEStop", "The e-stop", "none", "ubyte: 1 pressed, 0 released", _SAFETY, "RETURN_SINGLE"),
    (
        "safetyStatusSafetyLaser",
        "The safety laser's protective field",
        "none",
        "ubyte: 1 something inside it, 0 clear",
        _SAFETY,
        "RETURN_SINGLE",
    ),
    (
        "queryMotors",
        "Whether the motors are enabled",
        "none",
        "ubyte: 1 enabled, 0 disabled",
        _SAFETY,
        "RETURN_SINGLE",
    ),
    ("enableMotors", "Enables the motors", "none", "none", _SAFETY, "RETURN_NONE"),
    (
        "getBlockDriving",
        "Whether driving is blocked",
        "none",
        "ubyte: 1 blocked, 0 free",
        _SAFETY,
        "RETURN_SINGLE",
    ),
    (
        "DataStore_Laser_1_Zone",
        "The main laser's zone",
        "none",
        "string: value",
        "DataStore",
        "RETURN_SINGLE",
    ),
    (
        "SimulatorFault",
        "Raises a simulated fault that holds the motors until it is acknowledged",
        "none",
        "none",
        "CustomCommands",
        "RETURN_NONE",
    ),
)

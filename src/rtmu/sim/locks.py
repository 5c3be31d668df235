"""Mode locks on demand (a data module): put the simulator in the state ARIA's lock flags report.

``SimulatorLockStopMode`` stops the robot and locks the stop mode so that it will NOT unlock when
another mode asks (``getModeInfo``: locked 1, will unlock 0) — as a safety stop holds, and as the real
rig's ``RigLockStopMode`` does with ARIA's ``lockMode(false)``; a drive or a goal is then refused by
the lock, and ``stop`` still works. ``SimulatorLockStopModeYielding`` locks it the way ARNL's dock mode
locks (will unlock if asked: the asking mode takes over). ``SimulatorUnlockMode`` lifts either.
"""

from __future__ import annotations

from collections.abc import Iterable

from .catalogue import Row
from .handlers import Call, Handler, Reply


def _lock(will_unlock: bool):
    def handler(call: Call) -> Iterable[Reply]:
        world = call.world
        world.stop()
        if world.mode is world.stop_mode:
            world.stop_mode.lock = will_unlock
        world.check_mode_info()
        return ()

    return handler


def _unlock(call: Call) -> Iterable[Reply]:
    call.world.stop_mode.lock = None
    call.world.check_mode_info()
    return ()


ROWS: tuple[Row, ...] = (
    (
        "SimulatorLockStopMode",
        "Stops the robot and locks the stop mode: no other mode may take over, even when asked",
        "none",
        "none",
        "CustomCommands",
        "RETURN_NONE",
    ),
    (
        "SimulatorLockStopModeYielding",
        "Stops the robot and locks the stop mode, giving way when another mode asks (as docking does)",
        "none",
        "none",
        "CustomCommands",
        "RETURN_NONE",
    ),
    (
        "SimulatorUnlockMode",
        "Unlocks the stop mode locked by SimulatorLockStopMode",
        "none",
        "none",
        "CustomCommands",
        "RETURN_NONE",
    ),
)

HANDLERS: dict[str, Handler] = {
    "SimulatorLockStopMode": _lock(False),
    "SimulatorLockStopModeYielding": _lock(True),
    "SimulatorUnlockMode": _unlock,
}

"""The requests that change how the robot moves: the one list an observer may never send.

A request is a *motion request* when the server answers it by starting, changing or ending
motion — driving (``ratioDrive``, ARIA's ``driveJoystick``), stopping (``stop``: it ends a
navigation someone else started), jogging (``moveDist``, ``turnByAngle``, ``turnToHeading``),
wandering, and every navigation (ARNL's ``gotoGoal``, ``gotoPose``, ``home``, ``dock``,
``tourGoals``…, the LD robots' ``undock``, ``patrol``, ``gotoRouteGoal``). Reading the robot,
localizing it, pointing the camera head or changing the configuration are not.

Used by the client's role check (:mod:`rtmu.client.roles`), the replay link and the tests
(which assert that no observer put one on the wire). Names are ARIA's data names (case matters).
"""

from __future__ import annotations

from .errors import ProtocolError

RATIO_DRIVE = "ratioDrive"
"""``RatioDrive.DATA_NAME``, named here so that loading the role gate loads no payload (a test holds
the two equal)."""

MOTION_REQUESTS = frozenset(
    {
        # ARIA's own modes (ArServerModeRatioDrive, …Stop, …Drive, …Wander, …JogPosition)
        "ratioDrive", "stop", "driveJoystick", "wander", "moveDist", "turnByAngle", "turnToHeading",
        # ARNL navigation (ArServerModeGoto, ArServerModeDock) as the protocol notes list it
        "gotoGoal", "gotoPose", "home", "dock", "undock", "tourGoals", "tourGoalsInList", "TourGoalsInList",
        # Omron LD robots (ARAM)
        "patrol", "patrolRoute", "gotoRouteGoal",
    }
)  # fmt: skip
"""Every request that starts, changes or ends the robot's motion."""

STOPPING_REQUESTS = frozenset({"stop"})
"""Motion requests that only ever bring the robot to rest (a zero ``ratioDrive`` is one too)."""


def is_motion(name: str) -> bool:
    """True when sending ``name`` changes how the robot moves."""
    return name in MOTION_REQUESTS


def is_stopping(name: str, args: bytes) -> bool:
    """True when this motion request only stops: ``stop``, or ``ratioDrive`` asking for no motion.

    A ``ratioDrive`` whose arguments do not decode counts as driving (the server may read it so).
    """
    if name in STOPPING_REQUESTS:
        return True
    if name != RATIO_DRIVE:
        return False
    from .payloads.drive import RatioDrive  # here: every command's parser loads this module (roles)

    try:
        return not RatioDrive.decode(args).moving
    except ProtocolError:
        return False

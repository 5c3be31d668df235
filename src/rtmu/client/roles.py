"""Who a connection is: an OBSERVER never commands motion, an OPERATOR may — fixed at connect.

A recorder, a read-only bridge, ``watch``, ``status``, ``video`` and every other looking
command connect as observers: their client refuses to put any motion request
(:data:`rtmu.protocol.motion.MOTION_REQUESTS`) on the wire, on every path — the end of the
command, a signal, a lost link — so looking at a robot can never stop or steer it. The
window, ``rtmu drive`` and the navigation commands connect as operators.

An operator's gate also remembers whether this connection has *driven* (sent a motion
request that is not only a stop): a connection that ends stops the robot only for its own
drive, never for a navigation somebody else started.
"""

from __future__ import annotations

from enum import Enum

from ..protocol.motion import is_motion, is_stopping
from .errors import MotionRefused


class Role(Enum):
    OBSERVER = "observer"
    """Reads only: no motion request ever leaves this connection."""
    OPERATOR = "operator"
    """May drive, navigate and stop."""


class MotionGate:
    """The check every outgoing request of one connection passes (see the module notes)."""

    __slots__ = ("drove", "role")

    def __init__(self, role: Role) -> None:
        self.role = role
        self.drove = False
        """True once this connection sent a motion request that does more than stop."""

    def admit(self, name: str, args: bytes) -> None:
        """Raise :class:`MotionRefused` for an observer's motion request; note an operator's drive."""
        if not is_motion(name):
            return
        if self.role is not Role.OPERATOR:
            raise MotionRefused(name)
        if not is_stopping(name, args):
            self.drove = True

"""The session's side of the guardian process (:mod:`rtmu.guardian`): offer it the robot, beat, hear it.

The guardian is a separate process with its own login that stops the robot when this process is
killed, stopped by a signal, or silent past its lease while driving. A window's sessions share ONE
(``SessionConfig.guardian_seat``: a seat at the window's
:class:`~rtmu.guardian.shared.SharedGuardian`, armed for the selected robot only); a script that
drives (``SessionConfig(guardian=True)``: ``rtmu bridge --allow-drive``) has its own for each
connection. The drive loop asks :meth:`GuardianLink.waiting_reason` before a drive (none starts
while the guardian is still logging in to this robot), arms it before the first ``ratioDrive`` of
a drive and disarms it after its own stop; the network loop beats for it here while armed, the
window's GTK timer through ``ClientRunner.ui_heartbeat``.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable

from ..base.i18n import _
from ..base.notices import Kind, Level, Notice
from ..guardian.handle import BEAT_PERIOD
from ..guardian.messages import Hello
from ..guardian.shared import GuardianSeat, SharedGuardian
from ..values.target import Target
from .session_config import SessionConfig

log = logging.getLogger(__name__)

OWN_NAME = "this robot"
"""How a script's own guardian names its one robot ("Arming the guardian for this robot …")."""


class GuardianLink:
    """This session's guardian seat; every method runs on the network loop."""

    def __init__(self, notice: Callable[[Notice], None], config: SessionConfig) -> None:
        self._notice = notice
        self._timeout = config.connect_timeout
        self._own: SharedGuardian | None = None
        self.seat: GuardianSeat | None = config.guardian_seat
        """Where this session's records go (None: no guardian at all)."""
        if self.seat is None and config.guardian:
            # Its own process, started now: warm (imports done) by the time the connection is up, so
            # arming it is one login. Ended with the session (:meth:`end`).
            self._own = SharedGuardian()
            self.seat = self._own.seat(OWN_NAME)
            self._own.choose(self.seat)
        self._armed = False
        self.unavailable_reason: str | None = None
        """Why the guardian cannot stop this robot, once it said so (``rtmu why`` names it); else None."""

    def start(self, target: Target) -> None:
        """Connected to ``target`` (which offers ``ratioDrive``): the guardian may log in to it."""
        if self.seat is not None:
            self.seat.offer(Hello(target, self._timeout))

    def waiting_reason(self) -> str | None:
        """Why a drive may not start now (the guardian is still logging in to this robot), or None."""
        seat = self.seat
        return None if seat is None else seat.waiting_reason()

    def arm(self) -> None:
        seat = self.seat
        if seat is None:
            return
        seat.arm()
        if not self._armed:
            self._armed = True
            self._beat(seat)

    def _beat(self, seat: GuardianSeat) -> None:
        """The network thread's heartbeat to the guardian, every BEAT_PERIOD while armed."""
        if not self._armed or self.seat is not seat:
            return
        seat.beat_net()
        asyncio.get_running_loop().call_later(BEAT_PERIOD, self._beat, seat)

    def disarm(self) -> None:
        self._armed = False
        if self.seat is not None:
            self.seat.disarm()

    def close(self) -> None:
        """Our connection ended by our choice: the guardian leaves this robot."""
        self._armed = False
        if self.seat is not None:
            self.seat.withdraw(leave=True)

    def lost(self, *, driving: bool) -> None:
        """Our link died, not by our choice: while driving, only the guardian (its own link) can stop."""
        self._armed = False
        seat = self.seat
        if seat is None:
            return
        if driving:
            seat.halt()
        seat.withdraw(leave=False)  # its own login may well be alive: the reconnect finds it ready

    def end(self) -> None:
        """The session is closed: a guardian of its own ends (a shared one is the window's to end)."""
        self.close()
        own, self._own = self._own, None
        if own is not None:
            own.close()

    def poll(self) -> bool:
        """Hear what the guardian said; True when it stopped the robot (a drive must not resume)."""
        seat = self.seat
        if seat is None:
            return False
        stopped = False
        for word, text in seat.take_reports():
            if word == "stopped":
                stopped = True
                log.info("the guardian stopped the robot: %s", text)
                said = _("The guardian stopped the robot: {text}. Press again to drive.").format(text=text)
                self._notice(Notice.stopped(Kind.SAFETY, said, Level.ERROR))
            elif word == "unavailable":
                self.unavailable(text)
        return stopped

    def unavailable(self, reason: str) -> None:
        self.unavailable_reason = reason
        self._notice(
            Notice.warning(
                Kind.SAFETY,
                _(
                    "Guardian not available ({reason}): if this program is killed or frozen while driving, "
                    "only the server's own 2 s watchdog stops the robot"
                ).format(reason=reason),
            )
        )

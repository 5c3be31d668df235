"""The session's side of the guardian process (:mod:`rtmu.guardian`): start it, beat for it, hear it.

The guardian is a separate process with its own login that stops the robot when this process is
killed, stopped by a signal, or silent past its lease while driving. The drive loop arms it before
the first ``ratioDrive`` of a drive and disarms it after its own stop; the network loop beats for it
here, the window's GTK timer through ``ClientRunner.ui_heartbeat``.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable

from ..base.notices import Kind, Notice
from ..guardian.handle import BEAT_PERIOD, GuardianHandle
from ..guardian.messages import Hello
from .session_config import Target


class GuardianLink:
    """At most one guardian for the current connection; every method runs on the network loop."""

    def __init__(self, notice: Callable[[Notice], None], connect_timeout: float) -> None:
        self._notice = notice
        self._timeout = connect_timeout
        self.handle: GuardianHandle | None = None

    def start(self, target: Target) -> None:
        self.close(goodbye=True)
        try:
            self.handle = GuardianHandle.start(
                Hello(target.host, target.port, target.user, target.password, self._timeout)
            )
        except OSError as exc:
            self.unavailable(f"it could not be started: {exc.strerror or exc}")
            return
        self._beat(self.handle)

    def _beat(self, guardian: GuardianHandle) -> None:
        """The network thread's heartbeat to the guardian, every BEAT_PERIOD while it lives."""
        if self.handle is not guardian:
            return
        guardian.beat_net()
        asyncio.get_running_loop().call_later(BEAT_PERIOD, self._beat, guardian)

    def arm(self) -> None:
        if self.handle is not None:
            self.handle.arm()

    def disarm(self) -> None:
        if self.handle is not None:
            self.handle.disarm()

    def close(self, *, goodbye: bool) -> None:
        guardian, self.handle = self.handle, None
        if guardian is not None:
            guardian.close(goodbye=goodbye)

    def poll(self) -> bool:
        """Hear what the guardian said; True when it stopped the robot (a drive must not resume)."""
        guardian = self.handle
        if guardian is None:
            return False
        stopped = False
        for word, text in guardian.poll():
            if word == "stopped":
                stopped = True
                said = f"The guardian stopped the robot: {text}. Press again to drive."
                self._notice(Notice.error(Kind.SAFETY, said))
            elif word in ("unavailable", "lost", "ended"):
                self.handle = None
                guardian.close(goodbye=True)
                self.unavailable(text)
        return stopped

    def unavailable(self, reason: str) -> None:
        self._notice(
            Notice.warning(
                Kind.SAFETY,
                f"Guardian not available ({reason}): if this program is killed or frozen while driving, "
                "only the server's own 2 s watchdog stops the robot",
            )
        )

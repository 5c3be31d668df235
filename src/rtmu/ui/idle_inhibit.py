"""Keep the screen on while the robot moves: ``Gtk.Application.inhibit`` (idle and suspend), said so.

A tablet that locks its screen or suspends while the robot drives or navigates takes the operator's
view — and the window's heartbeat — away from a moving robot. While the robot shown is connected and
moves (a held drive, the server navigating, or its wheels turning), the application asks the desktop
not to idle or suspend, and the motion pill says "Screen kept on". It lets go
:data:`RELEASE_AFTER` seconds after the robot has come to rest (a pause between goals keeps it),
and at once when the link ends. A desktop that refuses (no session manager, as under Xvfb) gets no
claim in the window: it is said only when it holds.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

from ..base.i18n import N_, _  # noqa: E402
from ..model.observables import Phase, RobotModel  # noqa: E402

RELEASE_AFTER = 10.0
"""Seconds at rest before the desktop may idle again."""
MOVING_MM_S = 10.0
TURNING_DEG_S = 2.0
NOTE = N_("Screen kept on")
REASON = N_("A robot is moving under RTMU's control: the operator must keep seeing it")


class IdleInhibit:
    """See the module notes. ``refresh`` runs on the window's slow timer; ``say(text)`` shows the note."""

    def __init__(
        self,
        window: Gtk.ApplicationWindow,
        model: RobotModel,
        held: Callable[[], bool],
        say: Callable[[str], None],
        *,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.window, self.model, self.held, self.say, self.clock = window, model, held, say, clock
        self.cookie = 0
        """The desktop's inhibition cookie; 0 while none is held (or the desktop refused)."""
        self.asked = False
        """An inhibition was asked for and not yet let go (the desktop may have refused it)."""
        self._rest_since: float | None = None

    def moving(self) -> bool:
        """Connected, and the robot is driven, navigating or rolling."""
        m = self.model
        if m.connection.value.phase is not Phase.CONNECTED:
            return False
        robot = m.robot.value
        rolling = abs(robot.vel) > MOVING_MM_S or abs(robot.rot_vel) > TURNING_DEG_S
        return self.held() or m.navigation.value.navigating or rolling

    def refresh(self) -> None:
        if self.moving():
            self._rest_since = None
            if not self.asked:
                self._inhibit()
            return
        connected = self.model.connection.value.phase is Phase.CONNECTED
        now = self.clock()
        if self._rest_since is None:
            self._rest_since = now
        if self.asked and (not connected or now - self._rest_since >= RELEASE_AFTER):
            self.release()

    def _inhibit(self) -> None:
        app = self.window.get_application()
        if app is None:
            return
        flags = Gtk.ApplicationInhibitFlags.IDLE | Gtk.ApplicationInhibitFlags.SUSPEND
        self.cookie = app.inhibit(self.window, flags, _(REASON))
        self.asked = True
        self.say(_(NOTE) if self.cookie else "")

    def release(self) -> None:
        app = self.window.get_application()
        if self.cookie and app is not None:
            app.uninhibit(self.cookie)
        self.cookie = 0
        self.asked = False
        self.say("")

    def close(self) -> None:
        self.release()

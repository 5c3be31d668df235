"""The window's driving input: held drive keys, the on-screen STOP, and what ends a held drive.

Held motion happens only while the operator asks for it. A drive key drives while it is held
(``keys.KeyRouter`` tracks it by keycode and swallows its auto-repeat) — unless a pick mode gives
the arrows a second meaning (``keyboard_nav.pick_key``). What the window can no longer see let go
ends the drive: a focus loss, a menu or popover taking the keyboard, the process being suspended;
the keys then stay blocked in the controller until they are released. The on-screen STOP is the
same as Space (``stop_keys``): sent whatever the link looks like, and a finger on the D-pad or a
pick mode let go of. The D-pad's own hold is the map page's (``map_page``).
"""

from __future__ import annotations

from collections.abc import Callable

from ..base.i18n import _
from ..control.controller import KEYBOARD_LOST
from ..fleet.selected import SelectedRobot
from .keys import KeyRouter
from .map_page import MapPage


class DriveInput:
    """See the module notes. ``activate`` runs a key's action (``actions``); ``pick_key`` lets a pick
    mode take a drive key first (True: it did)."""

    def __init__(
        self,
        robot: SelectedRobot,
        map_page: MapPage,
        *,
        activate: Callable[[str], object],
        pick_key: Callable[[str], bool],
    ) -> None:
        self.robot, self.map_page, self._pick_key = robot, map_page, pick_key
        self.router = KeyRouter(hold=self.hold, release=self.release, activate=activate)
        """The capture-phase key router (the window adds its controller before the stop keys')."""

    def hold(self, name: str) -> None:
        # On the camera page too: the picture shows its age, and a fresh press is the operator's intent.
        if not self._pick_key(name):  # a pick mode's arrows move its point instead
            self.robot.session.controller.run(name)

    def release(self, name: str) -> None:
        self.robot.session.controller.release_command(name)

    def stop(self) -> None:
        """The on-screen STOP: the same as Space, and sent whatever the link looks like.

        Keys still held stay blocked by the controller until they are let go (as after Space), so
        their auto-repeat cannot start the robot again; a finger on the D-pad is let go of here.
        """
        self.robot.session.controller.stop()
        self.map_page.let_go()

    def popover_took_keys(self) -> None:
        """A menu or popover holds the keyboard now: held keys can no longer be seen let go."""
        self.robot.session.controller.look(_("the menu"), keys_leave=True)
        self.router.release_all()
        self.map_page.dpad.release_all()

    def focus_changed(self, active: bool) -> None:
        if active:
            self.robot.session.controller.focus_gained()  # key releases from now on are real ones
        else:
            self.end_held_drive(still_active=False)

    def end_held_drive(self, *, still_active: bool) -> None:
        """Stop, and forget held keys and fingers as on a focus loss: they stay blocked until released.

        ``still_active``: the window still has the keyboard (the process is being suspended), so a
        release seen afterwards is a real one and unblocks its key.
        """
        controller = self.robot.session.controller
        controller.focus_lost(_("RTMU was suspended (Ctrl+Z)") if still_active else KEYBOARD_LOST)
        self.router.release_all()
        self.map_page.dpad.release_all()
        if still_active:
            controller.focus_gained()

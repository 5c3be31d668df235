"""The window's timers: a window at rest wakes once a second; a held drive adds the fast ones.

The UI thread's heartbeat drives safety: while a drive is held, every
:data:`rtmu.control.held_drive.TICK` the lease is renewed (``controller.tick``) — if this loop ever
stalls, the lease lapses and the network side stops the robot — and every
:data:`GUARDIAN_BEAT` the guardian process hears that the UI lives. Both start when the controller
says a drive began (its ``View.driving``) and end once the drive is over and the guardian is
disarmed again. The slow timer (:data:`SLOW_TICK`) refreshes what ages without a new value (the
toolbar, the picture's age, a robot gone stale) and watches the network loop's lag; at rest the
window therefore wakes once a second, not 35 times (issue 28).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import GLib  # noqa: E402

from ..control.held_drive import TICK  # noqa: E402
from ..guardian.handle import BEAT_PERIOD as GUARDIAN_BEAT  # noqa: E402
from ..model.observables import Phase  # noqa: E402

if TYPE_CHECKING:
    from ..control.controller import Controller
    from ..fleet.sessions import RobotSession
    from ..model.observables import RobotModel
    from .banners import BannerStack
    from .camera_page import CameraPage
    from .desktop_citizen import DesktopCitizen
    from .map_page import MapPage
    from .motion import MotionIndicator
    from .notice_router import NoticeRouter
    from .toolbar import StatusToolbar
    from .why_hint import WhyHint

SLOW_TICK = 1.0
"""Seconds between the window's own ticks: ages (toolbar, picture), the stale look, the loop-lag watch."""


class TimedWindow(Protocol):
    """What the timers use of the window (``ui.window.MainWindow``, which imports this module)."""

    model: RobotModel
    map_page: MapPage
    toolbar: StatusToolbar
    camera_page: CameraPage
    notices: NoticeRouter
    why_hint: WhyHint
    banners: BannerStack
    motion: MotionIndicator
    desktop: DesktopCitizen

    @property
    def session(self) -> RobotSession: ...

    @property
    def controller(self) -> Controller: ...


class WindowTimers:
    """The slow tick always; the drive tick and the guardian beat from a drive's start to its end."""

    def __init__(self, window: TimedWindow) -> None:
        self.window = window
        self.ticks = 0
        """Counts the slow timer's ticks (once a second)."""
        self._slow = GLib.timeout_add(int(SLOW_TICK * 1000), self._slow_tick)
        self._drive = 0
        """The lease renewal (TICK) while a drive is held; 0 at rest."""
        self._beat = 0
        """The guardian's beat, from a drive's start until the guardian is disarmed; 0 at rest."""

    @property
    def fast_running(self) -> bool:
        """Whether a drive's timers run (tests: none at rest)."""
        return bool(self._drive or self._beat)

    def drive_started(self) -> None:
        """A drive began (the controller granted a lease) or a jog is watched: tick the controller
        (renew the lease, look for the jog's end) and beat for the guardian."""
        if not self._drive:
            self._drive = GLib.timeout_add(int(TICK * 1000), self._drive_tick)
        if not self._beat:
            self._beat = GLib.timeout_add(int(GUARDIAN_BEAT * 1000), self._beat_tick)
        self.window.map_page.refresh()

    def _driving(self) -> bool:
        return self.window.controller.needs_tick

    def _drive_tick(self) -> bool:
        """While a drive is held or a jog watched: renew the lease, look for the jog's end; the pill
        follows the keys. Ends with them."""
        self.window.controller.tick()
        self.window.map_page.refresh()
        self.window.why_hint.tick()
        self._place_banners()
        if self._driving():
            return True
        self._drive = 0
        return False

    def _place_banners(self) -> None:
        """The banners off the motion pills, and on a phone off the robot (``MapPage.banner_room``)."""
        w = self.window
        parent = w.banners.get_parent()
        # With no banner up there is nothing to keep off the robot: the robot's place on screen is not
        # worked out 10 times a second while driving for an empty column (only its margins reset).
        avoid: tuple[float, float, float, float] | None = None
        bottom = 0
        if parent is not None and w.banners.topics():
            avoid, bottom = w.map_page.banner_room(parent)
        w.banners.keep_clear_of(w.motion, w.camera_page.motion, avoid=avoid, bottom=bottom)

    def _beat_tick(self) -> bool:
        """The GTK thread's heartbeat to the guardian, until it is disarmed after the drive."""
        armed = self.window.session.runner.ui_heartbeat()
        if armed or self._driving():
            return True
        self._beat = 0
        return False

    def _slow_tick(self) -> bool:
        """Once a second: ages and staleness (nothing else changes them), the network loop's lag."""
        self.ticks += 1
        w = self.window
        w.map_page.refresh()
        w.why_hint.tick()  # a key held that drives nothing (no lease, so no drive tick) is seen here
        self._place_banners()
        w.toolbar.refresh()
        w.desktop.refresh()  # no screen lock or suspend while the robot moves
        w.camera_page.tick()
        loop_lag = getattr(w.controller.link, "loop_lag", None)  # a stalled network thread: said
        # A replay sends nothing (and its clock is the recording's): no "stops are not going out".
        connected = w.model.connection.value.phase is Phase.CONNECTED and not w.controller.replay
        w.notices.loop_lag(loop_lag() if callable(loop_lag) else None, connected)
        w.notices.link_health(w.model.health.value.level)
        return True

    def close(self) -> None:
        """Stop every timer (idempotent)."""
        for source in (self._slow, self._drive, self._beat):
            if source:
                GLib.source_remove(source)
        self._slow = self._drive = self._beat = 0

"""The window as a good citizen of the desktop: one part, so the window composes it in one line.

It holds :class:`~rtmu.ui.idle_inhibit.IdleInhibit` (no screen lock or suspend while the robot
moves, said in the motion pill) and :class:`~rtmu.ui.desktop_notify.DesktopNotifier` (notifications
while the window is away, each switched off in View ▸ Desktop notifications).
"""

from __future__ import annotations

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gio, Gtk  # noqa: E402

from ..model.observables import RobotModel  # noqa: E402
from .desktop_notify import DesktopNotifier  # noqa: E402
from .idle_inhibit import IdleInhibit  # noqa: E402
from .motion import MotionIndicator  # noqa: E402


class DesktopCitizen:
    """``inhibit`` and ``notifier``; :meth:`refresh` runs on the window's slow timer."""

    def __init__(
        self, window: Gtk.ApplicationWindow, model: RobotModel, motion: MotionIndicator, view_menu: Gio.Menu
    ) -> None:
        self.inhibit = IdleInhibit(window, model, held=lambda: bool(motion.held()), say=motion.set_note)
        self.notifier = DesktopNotifier(window, model, view_menu)

    def refresh(self) -> None:
        self.inhibit.refresh()

    def close(self) -> None:
        self.inhibit.close()
        self.notifier.close()

"""The robot the operator commands: a handle that always means the fleet's current selection.

Widgets hold this handle, never a robot: :meth:`SelectedRobot.ask` sends an intent through the
*selected* robot's controller guard, so after the operator selects robot 2 the camera head, live
video, layers, palette, configuration and patrol act on robot 2 — no widget can keep a stale
robot. What a widget holds *on* a robot (video playing, the head's position polled, the details'
strings watched) moves with the selection through :meth:`SelectedRobot.on_switch`.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import logging
from collections.abc import Callable
from typing import Any

from ..client.errors import ClientError
from ..values.intents import Intent
from .sessions import RobotSession

log = logging.getLogger(__name__)

Switch = Callable[[RobotSession, RobotSession], None]
"""``hook(old, new)``: the selection moved from ``old`` to ``new``."""


class SelectedRobot:
    """See the module notes. UI thread only."""

    def __init__(self, session: RobotSession) -> None:
        self.session = session
        self._hooks: list[Switch] = []

    def ask(self, intent: Intent) -> Any:
        """Send ``intent`` to the selected robot through its controller's guard (None when refused)."""
        return self.session.controller.ask(intent)

    def request(self, intent: Intent) -> concurrent.futures.Future[Any]:
        """:meth:`ask` for a widget that waits for the answer: a refusal (said already by the
        controller) comes back as a failed Future, so the widget's own waiting ends too."""
        future = self.ask(intent)
        if isinstance(future, concurrent.futures.Future):
            return future
        refused: concurrent.futures.Future[Any] = concurrent.futures.Future()
        refused.set_exception(ClientError(f"{intent.label}: refused"))
        return refused

    def show(self, session: RobotSession) -> None:
        """The selection moved (the fleet already stopped the robot selected before)."""
        old, self.session = self.session, session
        if old is session:
            return
        for hook in list(self._hooks):
            try:
                hook(old, session)
            except Exception:  # one widget's failure must not keep the others on the old robot
                log.exception("a widget failed to follow the selection")

    def on_switch(self, hook: Switch) -> Callable[[], None]:
        """Call ``hook(old, new)`` on every change of selection; returns the way to stop."""
        self._hooks.append(hook)

        def remove() -> None:
            with contextlib.suppress(ValueError):
                self._hooks.remove(hook)

        return remove

"""View ▸ Foxglove bridge: the window's robot, live, on a Foxglove WebSocket server (publishing only).

Starts a :class:`~rtmu.recorder.bridge.Bridge` on 127.0.0.1:8765 beside the session's other
taps (the recorder keeps its own), seeded with what the window shows now (robot, map,
connection), so Foxglove draws the map at once. From the window the bridge never drives:
the window's keys hold the drive lease, and two drivers on one lease would fight; driving
from Foxglove is ``rtmu bridge --allow-drive``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from ..base.i18n import _, error_words
from ..base.notices import Kind, Notice
from ..fleet.sessions import RobotSession
from ..recorder.topics import BRIDGE_PORT
from ..values.state import ConnectionChanged, MapChanged, RobotChanged, StateChange

if TYPE_CHECKING:  # foxglove's WebSocket server is loaded when the bridge is switched on
    from ..recorder.bridge import Bridge

HOST = "127.0.0.1"


class BridgeToggle:
    """``set(True)`` starts the bridge, ``set(False)`` ends it; ``tell`` says what happened."""

    def __init__(
        self,
        session: RobotSession,
        tell: Callable[[Notice], None],
        *,
        failed: Callable[[], None] | None = None,
        port: int = BRIDGE_PORT,
    ) -> None:
        self.session = session
        self.tell = tell
        self.failed = failed
        """Called when a start failed (the menu's check mark goes off again)."""
        self.port = port
        self.bridge: Bridge | None = None
        self._before: Callable[[StateChange], None] | None = None

    def set(self, on: bool) -> None:
        """Start or stop; a busy port leaves it off, with a notice and ``failed()``."""
        if on == (self.bridge is not None):
            return
        if not on:
            self._stop()
        elif not self._start() and self.failed is not None:
            self.failed()

    def _start(self) -> bool:
        from ..recorder.bridge import Bridge

        bridge = Bridge(host=HOST, port=self.port)
        try:
            bridge.start()
        except Exception as exc:
            self.tell(
                Notice.error(
                    Kind.RECORDING, _("Foxglove bridge not started: {exc}").format(exc=error_words(exc))
                )
            )
            return False
        self._attach(bridge)
        self.bridge = bridge
        self.tell(
            Notice.info(
                Kind.RECORDING,
                _("Foxglove bridge on ws://{HOST}:{port} (no drive)").format(HOST=HOST, port=bridge.port),
            )
        )
        return True

    def _attach(self, bridge: Bridge) -> None:
        """Publish this session's changes on ``bridge``, seeded with what the window shows now."""
        runner = self.session.runner
        before = self._before = runner.on_publish

        def both(change: StateChange) -> None:
            if before is not None:
                before(change)
            bridge.published(change)

        state = self.session.state
        for change in (
            ConnectionChanged(state.connection.value),
            MapChanged(state.map.value),
            RobotChanged(state.robot.value),
        ):
            bridge.published(change)
        runner.on_publish = both

    def _stop(self) -> None:
        bridge, self.bridge = self.bridge, None
        self.session.runner.on_publish = self._before
        if bridge is not None:
            bridge.close()
        self.tell(Notice.info(Kind.RECORDING, _("Foxglove bridge stopped")))

    def follow_selection(self, old: RobotSession, new: RobotSession) -> None:
        """The window shows another robot: the bridge publishes that one (it runs on, same port)."""
        bridge = self.bridge
        self.session = new
        if bridge is None:
            return
        old.runner.on_publish = self._before
        self._attach(bridge)
        self.tell(Notice.info(Kind.RECORDING, _("Foxglove bridge now shows {name}").format(name=new.name)))

    def close(self) -> None:
        if self.bridge is not None:
            self._stop()

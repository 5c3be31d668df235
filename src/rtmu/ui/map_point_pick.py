"""One point picked on the map for the map editor: a click sets it, a drag from it sets a heading.

Like ``pose_pick`` (the map's Go to point / Set position), but it only hands the pose to its asker
(the map edit window fills its fields) and never sends anything. One pick per start: the next
press on the map is the pick, then the map pans as always. While off, it denies every press at once.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

from .mapview import MapStage  # noqa: E402
from .pose_pick import DRAG_MIN_PX, capture_drag  # noqa: E402

Picked = Callable[[float, float, float | None], None]
"""``picked(x, y, heading)``: mm, mm, degrees (None: a click, no heading chosen)."""


class MapPointPick:
    """See the module notes."""

    def __init__(self, stage: MapStage) -> None:
        self.stage = stage
        self._picked: Picked | None = None
        self._pose: tuple[float, float, float | None] | None = None
        self.gesture = capture_drag(stage, self._begin, self._update, self._end)

    @property
    def active(self) -> bool:
        return self._picked is not None

    def start(self, picked: Picked) -> None:
        """The next press on the map picks (a drag from it chooses the heading)."""
        self._picked, self._pose = picked, None
        self.stage.set_cursor_from_name("crosshair")

    def cancel(self) -> None:
        self._picked, self._pose = None, None
        self.stage.set_cursor(None)

    def _begin(self, gesture: Gtk.GestureDrag, x: float, y: float) -> None:
        if self._picked is None:
            gesture.set_state(Gtk.EventSequenceState.DENIED)
            return
        gesture.set_state(Gtk.EventSequenceState.CLAIMED)
        wx, wy = self.stage.viewport.to_world(x, y)
        self._pose = (wx, wy, None)

    def _update(self, _gesture: Gtk.GestureDrag, dx: float, dy: float) -> None:
        if self._pose is not None and math.hypot(dx, dy) >= DRAG_MIN_PX:
            self._pose = (self._pose[0], self._pose[1], math.degrees(math.atan2(-dy, dx)))

    def _end(self, gesture: Gtk.GestureDrag, dx: float, dy: float) -> None:
        self._update(gesture, dx, dy)
        picked, pose = self._picked, self._pose
        self.cancel()
        if picked is not None and pose is not None:
            picked(*pose)

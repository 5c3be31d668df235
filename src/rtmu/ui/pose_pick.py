"""Picking a pose on the map: a click or tap sets the point, a drag from it sets the heading.

Two map modes use it — go to a point (``gotoPose``) and set the robot's position
(``localizeToPose``). While one is on, a press on the stage belongs to the picker (its drag
gesture runs in the capture phase and claims the press, so the stage does not pan); otherwise it
denies the press at once and the stage pans and zooms as always. The picker only records the pose
and shows it (``MapStage.marker``); sending it is the confirm bar's job (``pose_bar``), so a slip
of the finger never moves the robot.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import gi

gi.require_version("Gtk", "4.0")
from gi.repository import Gtk  # noqa: E402

from .mapview import MapStage  # noqa: E402
from .nav_draw import Marker, MarkerKind  # noqa: E402

DRAG_MIN_PX = 12.0
"""A press that moves less than this is a click (a point without a chosen heading)."""


def capture_drag(
    stage: MapStage,
    begin: Callable[[Gtk.GestureDrag, float, float], None],
    update: Callable[[Gtk.GestureDrag, float, float], None],
    end: Callable[[Gtk.GestureDrag, float, float], None],
) -> Gtk.GestureDrag:
    """A drag on the map seen before the map's own pan (capture phase): each pick mode and map tool
    claims a press it means and denies the rest, which the map then pans with."""
    gesture = Gtk.GestureDrag()
    gesture.set_propagation_phase(Gtk.PropagationPhase.CAPTURE)
    gesture.connect("drag-begin", begin)
    gesture.connect("drag-update", update)
    gesture.connect("drag-end", end)
    stage.add_controller(gesture)
    return gesture


class PosePicker:
    """The pick mode of one stage; ``changed()`` is called whenever the mode or the pose changes."""

    def __init__(self, stage: MapStage, changed: Callable[[], None] = lambda: None) -> None:
        self.stage = stage
        self.changed = changed
        self.kind: MarkerKind | None = None
        """The mode that is on (None: the map pans as usual)."""
        self.marker: Marker | None = None
        """The pose picked so far in this mode (None until the first click)."""
        self._press: tuple[float, float] | None = None
        self.gesture = capture_drag(stage, self._begin, self._update, self._update)

    @property
    def active(self) -> bool:
        return self.kind is not None

    def start(self, kind: MarkerKind) -> None:
        """Turn a mode on (or switch to the other one): the next click picks."""
        self.kind = kind
        self.marker = None
        self.stage.set_cursor_from_name("crosshair")
        self._show()

    def cancel(self) -> None:
        """Leave the mode; nothing is sent."""
        if self.kind is None and self.marker is None:
            return
        self.kind = None
        self.marker = None
        self._press = None
        self.stage.set_cursor(None)
        self._show()

    def set_marker(self, marker: Marker) -> None:
        """A pose chosen by keyboard (``keyboard_nav``): shown, and confirmed, like a click's."""
        if self.kind is not None:
            self.marker = marker
            self._show()

    def _show(self) -> None:
        self.stage.marker = self.marker
        self.stage.queue_draw()
        self.changed()

    # -- input -----------------------------------------------------------------------------------
    def _begin(self, gesture: Gtk.GestureDrag, x: float, y: float) -> None:
        if self.kind is None:
            gesture.set_state(Gtk.EventSequenceState.DENIED)
            return
        gesture.set_state(Gtk.EventSequenceState.CLAIMED)
        self._press = (x, y)
        wx, wy = self.stage.viewport.to_world(x, y)
        self.marker = Marker(self.kind, wx, wy, self._default_heading())
        self._show()

    def _update(self, _gesture: Gtk.GestureDrag, dx: float, dy: float) -> None:
        if self.kind is None or self._press is None or self.marker is None:
            return
        if math.hypot(dx, dy) < DRAG_MIN_PX:
            return
        th = math.degrees(math.atan2(-dy, dx))  # screen y is down, the map's y is up
        if self.marker.th != th:
            self.marker = Marker(self.marker.kind, self.marker.x, self.marker.y, th)
            self._show()

    def _default_heading(self) -> float | None:
        """Without a drag: a point to go to keeps any heading; a placed robot keeps the one it has."""
        if self.kind is MarkerKind.LOCALIZE:
            return self.stage.model.robot.value.th
        return None

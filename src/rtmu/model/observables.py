"""The UI thread's state: observables holding one robot's values, and the operator's own settings.

Confined to ONE thread (the UI thread): the network side hands typed changes
(:data:`rtmu.values.state.StateChange`) over through the runner's "post to UI"
function and :meth:`RobotModel.apply` stores them. Never imports GTK or asyncio.

Every part is an observable holding one frozen value. ``set(new)`` replaces the
value and calls the observers **only if the value really changed** — the
lesson of the original RTMU thesis, where an unchanged status still cost a
full redraw at every 200 ms update. Timestamps are kept on the values but are
declared ``compare=False``, so a fresh-but-identical status refreshes the
timestamps without waking anybody.

Two owners, kept apart so that a window can show any robot of a fleet:

* :class:`RobotModel` — what one robot and its link are (one per
  :class:`rtmu.fleet.sessions.RobotSession`): ``robot``, ``map``, ``camera``,
  ``connection``, ``health``, ``navigation`` and the ``trail`` it drove.
* :class:`OperatorState` — what the operator chose (one per window): ``speed``
  (the drive throttle step) and ``view`` (zoom, follow, layers).

The value types live in :mod:`rtmu.values.state` and are re-exported here.
"""

from __future__ import annotations

import dataclasses
import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

from ..values.commission import ScanState, TransfersState
from ..values.state import (
    CameraChanged,
    CameraImage,
    ConnectionChanged,
    ConnectionState,
    DrawingsChanged,
    DrawingsState,
    HealthChanged,
    LinkHealth,
    LinkLevel,
    MapChanged,
    MapModel,
    MapPhase,
    NavChanged,
    NavOutcome,
    NavState,
    Phase,
    PopupsChanged,
    PopupsState,
    RobotChanged,
    RobotState,
    ScanChanged,
    StateChange,
    TransfersChanged,
)

__all__ = [
    "CameraImage",
    "ConnectionState",
    "DrawingsState",
    "LinkHealth",
    "LinkLevel",
    "MapModel",
    "MapPhase",
    "NavOutcome",
    "NavState",
    "Observable",
    "OperatorState",
    "Phase",
    "PopupsState",
    "RobotModel",
    "RobotState",
    "ScanState",
    "SpeedSetting",
    "Trail",
    "TransfersState",
    "ViewOptions",
]

T = TypeVar("T")

Observer = Callable[[T, T], None]
"""Called as ``observer(old, new)`` after a real change."""


class Observable(Generic[T]):
    """One value and the observers that want to hear when it really changes.

    Not thread-safe on purpose: the model lives on the UI thread (see module notes).
    An observer that raises does not stop the others; the first error is re-raised
    after all observers ran, so a broken redraw is loud but cannot hide a change.
    """

    __slots__ = ("_observers", "_value")

    def __init__(self, value: T) -> None:
        self._value = value
        self._observers: list[Callable[[T, T], None]] = []

    @property
    def value(self) -> T:
        return self._value

    def observe(self, observer: Callable[[T, T], None]) -> Callable[[], None]:
        """Add an observer; returns a function that removes it again."""
        self._observers.append(observer)

        def remove() -> None:
            if observer in self._observers:
                self._observers.remove(observer)

        return remove

    def set(self, new: T) -> bool:
        """Store ``new``; notify observers and return True only if it differs from the old value.

        An equal value is still stored, so fields declared ``compare=False``
        (timestamps) stay fresh without costing a notification.
        """
        old = self._value
        self._value = new
        if old == new:
            return False
        error: BaseException | None = None
        for observer in list(self._observers):
            try:
                observer(old, new)
            except Exception as exc:  # one bad observer must not starve the others
                error = error or exc
        if error is not None:
            raise error
        return True

    def update(self, **changes: Any) -> bool:
        """``set(dataclasses.replace(value, **changes))`` for dataclass values."""
        return self.set(dataclasses.replace(self._value, **changes))  # type: ignore[type-var]


# -- one robot ----------------------------------------------------------------------------------

TRAIL_MAX = 1500
"""Poses kept in the trail (the oldest go first)."""
TRAIL_MIN_STEP_MM = 30.0
"""A pose closer than this to the last kept one is not added."""


class Trail:
    """Where the robot has been on the current map: a bounded list of (x, y) mm, oldest first.

    Cleared when a new map arrives and when the pose is forgotten (a disconnect);
    the view only draws it. ``observe`` hears every append and clear.
    """

    def __init__(self) -> None:
        self.points: deque[tuple[float, float]] = deque(maxlen=TRAIL_MAX)
        self._observers: list[Callable[[], None]] = []

    def observe(self, observer: Callable[[], None]) -> Callable[[], None]:
        self._observers.append(observer)

        def remove() -> None:
            if observer in self._observers:
                self._observers.remove(observer)

        return remove

    def robot_moved(self, old: RobotState, new: RobotState) -> None:
        if new.numbers_at is None:
            self.clear()
        elif (new.x, new.y) != (old.x, old.y) and (
            not self.points or math.dist(self.points[-1], (new.x, new.y)) >= TRAIL_MIN_STEP_MM
        ):
            self.points.append((new.x, new.y))
            self._changed()

    def map_changed(self, old: MapModel, new: MapModel) -> None:
        if new.generation != old.generation:
            self.clear()

    def clear(self) -> None:
        if self.points:
            self.points.clear()
            self._changed()

    def _changed(self) -> None:
        for observer in list(self._observers):
            observer()


class RobotModel:
    """One robot's observable state on the UI thread; a :class:`~rtmu.values.state.StateSink` for its
    runner."""

    def __init__(self) -> None:
        self.robot: Observable[RobotState] = Observable(RobotState())
        self.map: Observable[MapModel] = Observable(MapModel())
        self.camera: Observable[CameraImage | None] = Observable(None)
        self.connection: Observable[ConnectionState] = Observable(ConnectionState())
        self.health: Observable[LinkHealth] = Observable(LinkHealth())
        self.navigation: Observable[NavState] = Observable(NavState())
        self.popups: Observable[PopupsState] = Observable(PopupsState())
        self.drawings: Observable[DrawingsState] = Observable(DrawingsState())
        self.scan: Observable[ScanState] = Observable(ScanState())
        self.transfers: Observable[TransfersState] = Observable(TransfersState())
        self.trail = Trail()
        # The trail's observers run before any view's (added first), so a redraw sees the new point.
        self.robot.observe(self.trail.robot_moved)
        self.map.observe(self.trail.map_changed)

    def apply(self, change: StateChange) -> None:
        """Store a change from the network side (on the UI thread)."""
        match change:
            case RobotChanged(value):
                self.robot.set(value)
            case MapChanged(value):
                self.map.set(value)
            case CameraChanged(value):
                self.camera.set(value)
            case ConnectionChanged(value):
                self.connection.set(value)
            case HealthChanged(value):
                self.health.set(value)
            case NavChanged(value):
                self.navigation.set(value)
            case PopupsChanged(value):
                self.popups.set(value)
            case DrawingsChanged(value):
                self.drawings.set(value)
            case ScanChanged(value):
                self.scan.set(value)
            case TransfersChanged(value):
                self.transfers.set(value)


# -- operator settings ---------------------------------------------------------------------------

SPEED_MIN = 10
SPEED_MAX = 100
SPEED_STEP = 10


@dataclass(frozen=True, slots=True)
class SpeedSetting:
    """The drive throttle in percent: 10…100 in steps of 10 (the thesis's +/- keys)."""

    percent: int = 50

    def __post_init__(self) -> None:
        if not SPEED_MIN <= self.percent <= SPEED_MAX or self.percent % SPEED_STEP:
            raise ValueError(f"speed must be {SPEED_MIN}…{SPEED_MAX} in steps of {SPEED_STEP}")

    @classmethod
    def nearest(cls, percent: int) -> SpeedSetting:
        """The step at or below ``percent``, within 10…100 (a profile's saved speed)."""
        return cls(max(SPEED_MIN, min(SPEED_MAX, percent // SPEED_STEP * SPEED_STEP)))

    def faster(self) -> SpeedSetting:
        return SpeedSetting(min(SPEED_MAX, self.percent + SPEED_STEP))

    def slower(self) -> SpeedSetting:
        return SpeedSetting(max(SPEED_MIN, self.percent - SPEED_STEP))


@dataclass(frozen=True, slots=True)
class ViewOptions:
    zoom: float = 0.0
    """Map scale relative to 1 px = 10 mm at 1.0 (the view decides the exact meaning); 0 = fit."""
    follow_robot: bool = True
    show_sonar: bool = True


@dataclass(frozen=True, slots=True)
class NearPeople:
    """The operator's speed cap for work near people: on or off, and how fast at most (mm/s)."""

    on: bool = False
    mm_s: int = 250

    @property
    def cap(self) -> int | None:
        """The cap in force (None: off)."""
        return self.mm_s if self.on else None


class OperatorState:
    """What the operator chose, shared by every robot the window shows: speed step and view options."""

    def __init__(self) -> None:
        self.speed: Observable[SpeedSetting] = Observable(SpeedSetting())
        self.near_people: Observable[NearPeople] = Observable(NearPeople())
        self.view: Observable[ViewOptions] = Observable(ViewOptions())

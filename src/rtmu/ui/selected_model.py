"""The selected robot's state as one stable model, so the window's widgets never rebind.

The window's toolbar, map stage, camera, navigation panels and popups each observe a
:class:`~rtmu.model.observables.RobotModel` they were given once. In a fleet that model is a
:class:`SelectedModel`: it mirrors whichever robot is selected — its observables take
the selected robot's values and follow its changes, its trail *is* that robot's
trail — and :meth:`SelectedModel.show` moves it to another robot, every widget
hearing one ordinary change per part. GTK-free; UI thread only.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ..model.observables import Observable, RobotModel, Trail


def _observable_parts() -> tuple[str, ...]:
    """Every observable a :class:`RobotModel` has, read from one: a part added there is mirrored
    here without a second list to forget (a fleet window once lacked the drawings)."""
    probe = RobotModel()
    return tuple(name for name, value in vars(probe).items() if isinstance(value, Observable))


PARTS = _observable_parts()
"""The observables of a :class:`RobotModel` that are mirrored."""


class MirrorTrail(Trail):
    """The selected robot's trail: the same points, its changes heard here too."""

    def __init__(self) -> None:
        super().__init__()
        self._unhook: Callable[[], None] | None = None

    def follow(self, source: Trail) -> None:
        if self._unhook is not None:
            self._unhook()
        self.points = source.points
        self._unhook = source.observe(self._changed)
        self._changed()

    def close(self) -> None:
        if self._unhook is not None:
            self._unhook()
            self._unhook = None


class SelectedModel(RobotModel):
    """A :class:`RobotModel` that shows the state of the robot it was last pointed at (``show``).

    Built without :class:`RobotModel`'s own trail hooks: the trail is the source's, never
    appended to twice. ``apply`` is not used (the source's runner feeds the source).
    """

    def __init__(self, source: RobotModel) -> None:  # no super().__init__: see the class notes
        for part in PARTS:
            setattr(self, part, Observable(getattr(source, part).value))
        self.trail: Trail = MirrorTrail()
        self.source = source
        self._unhook: list[Callable[[], None]] = []
        self.show(source)

    def show(self, source: RobotModel) -> None:
        """Mirror ``source`` from now on: its current values are set at once (observers hear changes)."""
        for unhook in self._unhook:
            unhook()
        self.source = source
        self._unhook = [getattr(source, part).observe(self._forward(part)) for part in PARTS]
        assert isinstance(self.trail, MirrorTrail)
        self.trail.follow(source.trail)
        for part in PARTS:
            getattr(self, part).set(getattr(source, part).value)

    def _forward(self, part: str) -> Callable[[Any, Any], None]:
        mirror: Observable[Any] = getattr(self, part)

        def forward(_old: Any, new: Any) -> None:
            mirror.set(new)

        return forward

    def close(self) -> None:
        for unhook in self._unhook:
            unhook()
        self._unhook = []
        assert isinstance(self.trail, MirrorTrail)
        self.trail.close()

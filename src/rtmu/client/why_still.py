"""When the window offers "why won't it move?" by itself: a drive held a while and no motion.

Apart from :mod:`.why`'s rules, which the answer needs but the window's launch does not: the hint's
clock runs from the first held drive, the rules load with the first question (issue 28).
"""

from __future__ import annotations

HINT_AFTER = 1.0
"""Seconds a held drive may produce no motion before the window offers its answer."""


class StillWhileHeld:
    """When to offer "why won't it move?" on its own: a drive held :data:`HINT_AFTER` s without the
    robot moving. Fed by the window on its own clock; says True once per held drive."""

    def __init__(self, after: float = HINT_AFTER) -> None:
        self.after = after
        self._since: float | None = None
        self._said = False

    def update(self, now: float, driving: bool, moving: bool) -> bool:
        """``driving``: a drive is held now; ``moving``: the last status shows the robot moving."""
        if not driving or moving:
            self._since, self._said = None, False
            return False
        if self._since is None:
            self._since = now
        if self._said or now - self._since < self.after:
            return False
        self._said = True
        return True

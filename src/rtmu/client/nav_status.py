"""What an ARNL-class server's mode name and status string say about navigation (pure, no I/O).

ARNL reports navigation only in words: its ``Goto`` mode says ``Going to Lab B``, then ``Arrived at
Lab B`` or ``Failed to get to Lab B because robot lost``; its ``dock`` mode says ``Going to dock at
Charger``, ``Driving into dock``, then ``Docked`` or ``Failed dock``. The window's session and the
command line both read those words here, so they agree on what "arrived" and "failed" mean.

Server text is untrusted: everything kept is cut to :data:`MAX_TEXT` characters (escaping for a
terminal or a label is the printer's job).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

from ..base.i18n import N_, Said, as_said
from ..values.state import NavOutcome

MAX_TEXT = 200
"""Longest status, target or reason kept from the server."""

NAV_MODES = frozenset({"Goto", "dock", "Dock"})
"""``getModeInfo`` names of ARNL's navigation modes (``ArServerModeGoto``, ``ArServerModeDock``)."""

NAV_DATA = (
    "gotoGoal",
    "gotoPose",
    "home",
    "tourGoals",
    "dock",
    "undock",
    "localizeToPose",
    "getLocState",
    "getPath",
    "pathPlannerStatus",
    "goalName",
    "getGoals",
    "goalsUpdated",
    "gotoRouteGoal",
    "dockInfo",
)
"""The data navigation uses, where listed (the session's ``NavState.offered`` is these)."""

LOST = N_("the robot is lost")
"""ARNL's ``because robot lost``, in plain words."""
NO_PATH = N_("no path could be planned")
"""ARNL's ``Failed to plan to …``, which gives no reason of its own."""
OWN_REASONS = frozenset({LOST, NO_PATH})
"""Reasons in RTMU's words (said in the operator's language); any other reason is the server's."""

_GOING = ("Going to ", "Returning home", "Touring to ", "Driving into dock", "Docking")
_FAILED = ("Failed", "Unable to dock", "Cannot drive to dock")


@dataclass(frozen=True, slots=True)
class NavReading:
    """One status string, read: the phase, where to, why it failed, and the text itself (bounded)."""

    phase: NavOutcome
    """``NONE`` (no news), ``GOING`` or how it ended (never ``CANCELLED``: only a change of words says so)."""
    target: str = ""
    reason: str = ""
    text: str = ""

    @property
    def finished(self) -> bool:
        return self.phase in (NavOutcome.ARRIVED, NavOutcome.DOCKED, NavOutcome.FAILED)

    def sentence(self) -> str:
        """The outcome for the operator: ``Arrived at Lab B``, ``Failed to get to Lab B because the
        robot is lost``, ``Docked``; "" while not finished. The server's words are kept as sent; a
        reason of RTMU's own (:data:`LOST`, :data:`NO_PATH`) joins them as a :class:`Said`, so the
        operator reads it in their language and ``--json`` in English."""
        if not self.finished:
            return ""
        if self.phase is NavOutcome.FAILED:
            head = _failure_head(self.text)
            if self.reason and self.reason not in head:
                reason = as_said(self.reason) if self.reason in OWN_REASONS else self.reason
                return Said(N_("{outcome_text} because {reason}"), outcome_text=head, reason=reason)
            return head
        return self.text


def _bounded(text: str) -> str:
    return text[:MAX_TEXT]


def read_motion(status: str, mode_name: str = "", dock_state: str | None = None) -> NavReading:
    """What the robot is doing on its own, for the window and the command line alike: the status read
    by :func:`read_status`, with an LD robot's ``dockInfo`` state (``dock_state``) answering unless the
    status says it is on its way somewhere — its status may still read "Arrived at …" from the goto
    before the dock."""
    reading = read_status(status, mode_name)
    if reading.phase is not NavOutcome.GOING and dock_state in ("Docking", "Docked"):
        phase = NavOutcome.GOING if dock_state == "Docking" else NavOutcome.DOCKED
        return NavReading(phase, "dock", text=dock_state)
    return reading


def read_status(status: str, mode_name: str = "") -> NavReading:
    """Read one ``updateStrings`` status; ``mode_name`` (``getModeInfo``, "" if unknown) keeps a
    ``Going to …`` of some other mode from counting as navigation."""
    text = _bounded(status.strip())
    if text == "Docked":
        return NavReading(NavOutcome.DOCKED, "dock", text=text)
    if text.startswith("Arrived at "):
        return NavReading(NavOutcome.ARRIVED, text.removeprefix("Arrived at "), text=text)
    if text == "Returned home":
        return NavReading(NavOutcome.ARRIVED, "home", text=text)
    if text.startswith(_FAILED):
        return NavReading(NavOutcome.FAILED, _failure_target(text), _failure_reason(text), text)
    if text.startswith(_GOING) and (not mode_name or mode_name in NAV_MODES):
        return NavReading(NavOutcome.GOING, _going_target(text), text=text)
    return NavReading(NavOutcome.NONE, text=text)


def _going_target(text: str) -> str:
    if text.startswith("Returning home"):
        return "home"
    if text.startswith(("Driving into dock", "Docking")):
        return "dock"
    for prefix in ("Going to ", "Touring to "):
        if text.startswith(prefix):
            return text.removeprefix(prefix)
    return ""


def _failure_head(text: str) -> str:
    """``Failed to get to Lab B`` out of ``… because robot lost`` or ``… (path blocked)``."""
    head = text.split(" because ", 1)[0]
    if head.endswith(")") and " (" in head:
        head = head.rsplit(" (", 1)[0]
    return head.strip()


def _failure_target(text: str) -> str:
    head = _failure_head(text)
    for prefix in ("Failed to get to ", "Failed to plan to "):
        if head.startswith(prefix):
            return head.removeprefix(prefix)
    if head.startswith("Failed to get home"):
        return "home"
    if "dock" in head.lower():
        return "dock"
    if head.startswith("Failed touring"):
        return "tour"
    return ""


def _failure_reason(text: str) -> str:
    """Why, in plain words: ARNL's ``because robot lost`` reads as ``the robot is lost``."""
    if " because " in text:
        why = text.split(" because ", 1)[1].strip().rstrip(".")
        return LOST if why == "robot lost" else why
    if text.endswith(")") and " (" in text:
        return text.rsplit(" (", 1)[1][:-1].strip()
    if text.startswith("Failed to plan to "):
        return NO_PATH
    if text.startswith("Failed touring goals:"):
        return text.split(":", 1)[1].strip().rstrip(".")
    return ""


def path_remaining(x: float, y: float, path: Sequence[tuple[int, int]]) -> float | None:
    """mm left along ``path`` (corners still ahead, in order) from the robot at (x, y); None if empty."""
    if not path:
        return None
    total = math.hypot(path[0][0] - x, path[0][1] - y)
    for (ax, ay), (bx, by) in itertools.pairwise(path):
        total += math.hypot(bx - ax, by - ay)
    return total

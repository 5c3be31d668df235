"""What ``rtmu doctor`` finds, step by step: each step's result, the features a data list gives the
operator, and the report in words. Split from :mod:`.doctor` (which runs the steps on the wire)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ..base.i18n import _, words
from ..base.textsafe import visible

if TYPE_CHECKING:
    from ..client.diagnosis import Step

FEATURES: tuple[tuple[str, str, tuple[str, ...]], ...] = (
    ("teleop", "drive with the keys", ("ratioDrive",)),
    ("stop", "stop button", ("stop",)),
    ("navigation", "go to goals and poses", ("gotoGoal", "gotoPose", "goto", "gotoRouteGoal")),
    ("map", "map download", ("getMapBinary", "getMap")),
    ("camera", "camera pictures", ("getPicture*", "sendVideo", "getVideo*")),
    ("sensors", "sonar and laser drawing", ("sonarCurrent", "Laser_*Current", "getSensorCurrent")),
    ("configuration", "server configuration (ArConfig)", ("getConfigBySections*", "setConfig")),
    ("popups", "the robot's message boxes", ("popupCreate",)),
    ("custom_commands", "the robot's custom commands", ("listCommands", "listStringCommands")),
    ("status", "pose, battery and status", ("updateNumbers", "update")),
)
"""(key, what it gives the operator, data names — a trailing ``*`` matches a prefix)."""


@dataclass
class StepResult:
    step: Step
    result: str
    """``ok``, ``fail``, ``warn`` (not fatal), ``not_checked`` or ``skipped`` (an earlier step failed)."""
    summary: str
    advice: str = ""
    details: dict[str, Any] = field(default_factory=dict)

    def as_json(self) -> dict[str, Any]:
        return {
            "step": self.step.key,
            "title": self.step.title,
            "result": self.result,
            "summary": self.summary,
            "advice": self.advice,
            **self.details,
        }


class StepFailed(Exception):
    def __init__(self, result: StepResult) -> None:
        super().__init__(result.summary)
        self.result = result


def fail(step: Step, summary: str, advice: str = "", **details: Any) -> StepFailed:
    return StepFailed(StepResult(step, "fail", summary, advice, dict(details)))


def features_of(names: set[str]) -> dict[str, bool]:
    def offered(pattern: str) -> bool:
        if pattern.endswith("*"):
            return any(n.startswith(pattern[:-1]) for n in names)
        if "*" in pattern:
            head, tail = pattern.split("*", 1)
            return any(n.startswith(head) and n.endswith(tail) for n in names)
        return pattern in names

    return {key: any(offered(p) for p in patterns) for key, _, patterns in FEATURES}


MARKS = {"ok": "ok  ", "fail": "FAIL", "warn": "warn", "not_checked": "--  ", "skipped": "..  "}


def report_lines(
    steps: Sequence[StepResult], host: str, port: int, user: str, failed: StepResult | None, code: int
) -> list[str]:
    """The human report, step by step (printed, and kept as the last one), in the operator's language;
    the ``--json`` report keeps the English (:meth:`StepResult.as_json`)."""
    lines = [f"rtmu doctor {host}:{port}" + (_(" (user {user})").format(user=user) if user else "")]
    for s in steps:
        lines.append(f"  [{MARKS.get(s.result, s.result)}] {_(s.step.title)}: {visible(words(s.summary))}")
        if s.advice:
            lines.append("       " + _("  what to do: {visible}").format(visible=visible(words(s.advice))))
    if failed is None:
        lines.append(_("All steps passed: RTMU can connect to this robot."))
    else:
        lines.append(
            _("Stopped at the {step} step (exit {code}).").format(step=_(failed.step.title), code=code)
        )
    return lines

"""The words the window uses for navigation: which motion is happening, where to, how localized.

Pure text from :class:`rtmu.model.observables.NavState` (no widgets), so the sentences are tested without a
display and the toolbar, the motion indicator and the link banner all say the same thing. Names
in them come from the server and are shown as plain text by the labels that use them.
"""

from __future__ import annotations

from ..base.i18n import N_, _
from ..base.units import metres
from ..client.nav_status import OWN_REASONS
from ..model.observables import NavState

POOR_SCORE = 0.6
"""A localization score below this (0–1) is shown as poor (amber) even while the state is Good."""


def loc_level(state: str | None, score: float | None) -> str | None:
    """``good`` / ``poor`` / ``lost`` (the toolbar cell's CSS class), None when not offered."""
    if state is None:
        return None
    if state == "Lost":
        return "lost"
    if state == "Good" and (score is None or score >= POOR_SCORE):
        return "good"
    return "poor"


def loc_text(state: str | None, score: float | None) -> str:
    """``Good 95 %``; the state alone when there is no score."""
    if state is None:
        return ""
    return state if score is None else f"{state} {round(score * 100)} %"


def where(target: str) -> str:
    """A target in a sentence: ``Lab B``, ``the point``, ``home``, ``the dock``."""
    return {"point": _("the point"), "dock": _("the dock"), "": _("a goal")}.get(target, target)


def going_text(nav: NavState) -> str:
    """``Going to Lab B — 12.4 m left`` (``Going home``; no distance until a path is known)."""
    head = _head(nav)
    if nav.remaining_mm is not None:
        head += _(" — {distance} left").format(distance=metres(nav.remaining_mm))
    return head


def _head(nav: NavState) -> str:
    return _("Going home") if nav.target == "home" else _("Going to {where}").format(where=where(nav.target))


HELD_BY = {
    "keys": N_("Driving (held keys)"),
    "dpad": N_("Driving (D-pad held)"),
    "pad": N_("Driving (gamepad)"),
}
"""The held drive's title by what holds it: the operator lets go of the thing named."""


def motion_text(nav: NavState, *, held: bool, link_up: bool, by: str = "keys") -> tuple[str, tuple[str, ...]]:
    """(kind, lines) for the motion indicator; kind ``autonomous``, ``held`` or "" (hidden);
    ``by`` is what holds a drive (a :data:`HELD_BY` key).

    Short lines (title, where to, how far and how to end it) keep the pill narrow, clear of the
    banners; a long goal name is cut on its own line, never the distance.
    Autonomy wins when both are true for a moment (a key press cancels navigation, and the
    indicator follows once the server has said so). A lost link is said by the link banner alone
    (see :func:`link_lost_note`): one place, not two.
    """
    if not link_up:
        return "", ()
    if nav.navigating:
        dest = _("Going home") if nav.target == "home" else _("To {where}").format(where=where(nav.target))
        left = (
            ""
            if nav.remaining_mm is None
            else _("{distance} left · ").format(distance=metres(nav.remaining_mm))
        )
        return "autonomous", (
            _("Navigating (autonomous)"),
            dest,
            _("{left}Space or STOP cancels").format(left=left),
        )
    if held:
        return "held", (_(HELD_BY.get(by, HELD_BY["keys"])), _("Let go to stop"))
    return "", ()


def link_lost_note(nav: NavState) -> str:
    """What the link banner adds while the robot navigates with no link: it is on its own."""
    if not nav.navigating:
        return ""
    head = _head(nav)
    return _(" The robot is navigating on its own ({lower}{value}); STOP stays available.").format(
        lower=head[0].lower(), value=head[1:]
    )


def outcome_status(nav: NavState) -> str:
    """The status column's words for how the last navigation ended ("" while none has)."""
    if not nav.outcome_text:
        return ""
    if nav.reason and nav.reason not in nav.outcome_text:
        reason = _(nav.reason) if nav.reason in OWN_REASONS else nav.reason  # ours: translated
        return _("{outcome_text} because {reason}").format(outcome_text=nav.outcome_text, reason=reason)
    return nav.outcome_text

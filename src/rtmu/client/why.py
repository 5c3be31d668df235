"""Why won't it move? — what RTMU knows or can ask, told as one plain sentence with its fix (no I/O).

"It won't move" is the call robot support gets most. :func:`diagnose` reads :class:`Facts` — the
server's own data, gathered by :mod:`rtmu.client.why_gather` (the command line) or filled in by the
window from what its session already holds, plus our own side (link, lease, guardian) — and answers
with the causes it finds, the most fundamental first, each a sentence, its fix and what ``--fix``
may do about it. A cause is named only when the server's data says so; nothing is guessed. Values
RTMU cannot interpret (an Omron LD robot's safety data, whose layouts are not public) come back
raw, labelled as such, and are never acted on without the operator's confirmation.

What ARIA 2.9.1 itself puts on the wire (learnt from its sources): the active mode's lock
(``getModeInfo``: locked, will / will not unlock if asked — a locked mode gives way only when
another mode asks to take over and it agrees), ``ratioDrive`` in group Movement and ``stop`` in
Stop (a login's data list holds only what its groups allow), safe drive (``getSafeDrive``; its
limiter's ``Clearance``/``PaddingAtSlowSpeed`` parameters in the Teleop section), the teleop
watchdog (``Timeout``), and the status words ``Stalled`` / ``Bumped``. ArRobot's e-stop and
motor-enable flags are not sent by ArServerInfoRobot: RTMU names those only where a server's own
status words say so.
"""

from __future__ import annotations

import math
import re

from ..base.i18n import N_, Said
from ..base.units import Quantity
from ..protocol.payloads.drive import RATIO_ROT_DEAD_ZONE, RATIO_TRANS_DEAD_ZONE, RatioDrive
from ..protocol.payloads.robot import ModeInfo
from ..values.state import LinkLevel, NavOutcome
from .lease import RESEND_PERIOD
from .nav_status import read_status
from .why_safe_drive import safe_drive_rule
from .why_values import (
    Answer,
    Cause,
    Facts,
    Fix,
    Motion,
    Reason,
)

# -- the rules -----------------------------------------------------------------------------------
WATCHDOG_MARGIN = 2.0
"""A server watchdog shorter than this many of RTMU's resend periods stops drives between commands."""
_ESTOP = re.compile(r"\be-?stop\b|\bemergency[ -]stop\b", re.IGNORECASE)
_ESTOP_CLEAR = re.compile(r"\b(relieved|released|not pressed|clear(ed)?|ok)\b", re.IGNORECASE)
_MOTORS_OFF = re.compile(r"\bmotors?\b[^.\n]{0,20}\b(disabled|off)\b", re.IGNORECASE)
_STALL_WORDS = ("Stalled", "Bumped")
"""ArServerModeRatioDrive's / ArServerModeDrive's status when a motor stalls or the stall value
(bumpers) is set."""
DOCK_MODES = frozenset({"dock", "Dock"})
NOT_FOR_NAVIGATION = "driving by hand is not held back, but navigation is: "
"""How a cause that holds back only navigation (a lost localization) is noted in a hand-drive answer."""


def diagnose(facts: Facts, motion: Motion | None = None, *, navigate: bool = False) -> Answer:
    """Every cause the facts show, in :class:`Cause` order. ``motion``: the drive asked for (an
    obstacle then matters only in its direction); ``navigate``: the question is about navigation
    (a lost localization counts)."""
    found: list[Reason] = []
    for rule in _RULES:
        found.extend(rule(facts, motion, navigate))
    order = list(Cause)
    found.sort(key=lambda r: order.index(r.cause))
    notes = list(facts.notes)
    if facts.ours.guardian:
        notes.append(Said(N_("the guardian is not watching this drive ({why})"), why=facts.ours.guardian))
    if not navigate:  # driving by hand needs no localization, but the operator may mean to navigate next
        notes += [
            NOT_FOR_NAVIGATION + r.sentence() for r in _modes(facts, motion, True) if r.cause is Cause.LOST
        ]
    return Answer(tuple(found), tuple(notes), facts.raw)


def _words(facts: Facts) -> list[str]:
    """The server's own status lines (status, then each line of the extended status)."""
    lines = [facts.status, *facts.extended_status.splitlines()]
    return [line.strip() for line in lines if line.strip()]


def _quote(text: str) -> str:
    return '"' + text[:120] + '"'


def _our_side(facts: Facts, motion: Motion | None, navigate: bool) -> list[Reason]:
    ours = facts.ours
    out: list[Reason] = []
    if ours.link in (LinkLevel.STALE, LinkLevel.LOST, LinkLevel.DOWN):
        said = {
            LinkLevel.STALE: N_("stale (no status in time)"),
            LinkLevel.LOST: N_("lost"),
            LinkLevel.DOWN: N_("down (not connected)"),
        }[ours.link]
        out.append(
            Reason(
                Cause.LINK,
                Said(N_("our link to the robot is {state}: RTMU sends no drive over it"), state=Said(said)),
                N_("check the network (Wi-Fi, cable); once the link is back, press the drive key again"),
                (f"link: {ours.link.value}",),
            )
        )
    if ours.replay:
        out.append(
            Reason(
                Cause.LEASE,
                N_("this is a replay: nothing is sent to a robot"),
                N_("connect to the robot to drive it"),
            )
        )
    elif ours.keys_blocked:
        out.append(
            Reason(
                Cause.LEASE,
                N_("a drive key held through a stop is ignored until it is released"),
                N_("let go of the key and press it again"),
            )
        )
    elif ours.lease_ended == "lapsed":
        out.append(
            Reason(
                Cause.LEASE,
                N_(
                    "the window did not renew the drive in time (it was busy or frozen), "
                    "so RTMU stopped the robot"
                ),
                N_("press the drive key again"),
            )
        )
    return out


def _rights(facts: Facts, motion: Motion | None, navigate: bool) -> list[Reason]:
    who = (
        Said(N_("user {user}"), user=repr(facts.user))
        if facts.user
        else Said(N_("this login (no user name)"))
    )
    drive, stop = "ratioDrive" in facts.offers, "stop" in facts.offers
    out: list[Reason] = []
    if not drive:
        problem = Said(N_("{who} may not drive the robot (no ratioDrive in its data list)"), who=who)
        if not stop:
            problem = Said(
                N_("{who} may neither drive nor stop the robot (no ratioDrive, no stop in its data list)"),
                who=who,
            )
        advice = (
            N_("log in as a user whose groups include Movement (and Stop)")
            if facts.user
            else N_("this server offers no driving without a login: log in as a user with Movement")
        )
        out.append(Reason(Cause.NO_DRIVE, problem, advice, (N_("data list: no ratioDrive"),)))
    if not stop:
        out.append(
            Reason(
                Cause.NO_STOP,
                Said(
                    N_(
                        "SAFETY: {who} may not send stop (no stop in its data list): RTMU's STOP cannot stop "
                        "the robot from this login{but}"
                    ),
                    who=who,
                    but=Said(N_(" except by zero drive ratios")) if drive else "",
                ),
                N_("do not drive from this login; use one whose groups include Stop"),
                (N_("data list: no stop"),),
                loud=True,
            )
        )
    return out


def _dead_zone(facts: Facts, motion: Motion | None, navigate: bool) -> list[Reason]:
    """The drive asked for is one ARIA's ratio drive ignores: it is the request, not the robot."""
    if (
        motion is None
        or "ratioDrive" not in facts.offers
        or not RatioDrive(motion.trans, motion.rot).in_dead_zone
    ):
        return []
    return [
        Reason(
            Cause.DEAD_ZONE,
            Said(
                N_(
                    "the drive asked for (translation {trans}, rotation {rot}) is inside ARIA's dead zone "
                    "(translation up to ±{trans_zone}, rotation under ±{rot_zone}): the server ignores it"
                ),
                trans=Quantity(motion.trans, "%", None),
                rot=Quantity(motion.rot, "%", None),
                trans_zone=Quantity(RATIO_TRANS_DEAD_ZONE, "%", None),
                rot_zone=Quantity(RATIO_ROT_DEAD_ZONE, "%", None),
            ),
            Said(
                N_("ask for more than {trans_zone} translation or at least {rot_zone} rotation"),
                trans_zone=Quantity(RATIO_TRANS_DEAD_ZONE, "%", None),
                rot_zone=Quantity(RATIO_ROT_DEAD_ZONE, "%", None),
            ),
            (
                Said(
                    N_("our ratioDrive: {trans} translation, {rot} rotation"),
                    trans=Quantity(motion.trans, "%", None),
                    rot=Quantity(motion.rot, "%", None),
                ),
            ),
        )
    ]


def _safety_words(facts: Facts, motion: Motion | None, navigate: bool) -> list[Reason]:
    out: list[Reason] = []
    lines = _words(facts)
    estop = next((w for w in lines if _ESTOP.search(w) and not _ESTOP_CLEAR.search(w)), None)
    if estop is not None:
        out.append(
            Reason(
                Cause.ESTOP,
                Said(N_("the robot's e-stop is pressed (the server says {words})"), words=_quote(estop)),
                N_(
                    "make it safe, release the e-stop button on the robot, "
                    "then reset it as the robot requires"
                ),
                (f"status: {_quote(estop)}",),
            )
        )
    motors = next((w for w in lines if _MOTORS_OFF.search(w)), None)
    if motors is not None:
        out.append(
            Reason(
                Cause.MOTORS,
                Said(N_("the robot's motors are disabled (the server says {words})"), words=_quote(motors)),
                _motors_advice(facts),
                (f"status: {_quote(motors)}",),
                _enable_fix(facts),
            )
        )
    if facts.faults:
        shown = "; ".join(f[:120] for f in facts.faults[:5]) + (" …" if len(facts.faults) > 5 else "")
        fix = None
        if "acknowledgeFault" in facts.offers:
            fix = Fix(
                "acknowledge_faults",
                N_(
                    "acknowledge the listed faults on the robot (acknowledgeFault; "
                    "its layout is not public: RTMU builds it from the server's own description)"
                ),
                "acknowledgeFault",
                confirm=True,
            )
        out.append(
            Reason(
                Cause.FAULTS,
                Said(
                    N_("the robot reports {count} fault(s): {faults}"), count=len(facts.faults), faults=shown
                ),
                N_("clear what caused them, then acknowledge them (with care: the robot may move on)"),
                ("getFaults",),
                fix,
            )
        )
    return out


def _motors_advice(facts: Facts) -> str:
    if "enableMotors" in facts.offers:
        return N_("find out why they were disabled (e-stop, a fault), then enable them again (enableMotors)")
    return N_("find out why they were disabled (e-stop, a fault) and enable them on the robot")


def _enable_fix(facts: Facts) -> Fix | None:
    if "enableMotors" not in facts.offers:
        return None
    return Fix(
        "enable_motors",
        N_("enable the motors (enableMotors; its layout is not public)"),
        "enableMotors",
        True,
    )


def _battery(facts: Facts, motion: Motion | None, navigate: bool) -> list[Reason]:
    level, shutdown = facts.battery, facts.battery_shutdown
    if level is None or shutdown is None or level > shutdown:
        return []
    unit = "%" if facts.battery_soc else "V"
    return [
        Reason(
            Cause.BATTERY,
            Said(
                N_("the battery ({level}) is at or below the robot's shutdown level ({shutdown})"),
                level=Quantity(level, unit, None),
                shutdown=Quantity(shutdown, unit, None),
            ),
            N_("charge the robot (dock it or plug it in) before driving"),
            (
                Said(N_("updateNumbers: battery {level}"), level=Quantity(level, unit, None)),
                Said(N_("batteryInfo: shutdown {level}"), level=Quantity(shutdown, unit, None)),
            ),
        )
    ]


def _stalled(facts: Facts, motion: Motion | None, navigate: bool) -> list[Reason]:
    word = next((w for w in _words(facts) if w in _STALL_WORDS), None)
    if word is None:
        return []
    what = (
        N_("a motor is stalled")
        if word == "Stalled"
        else N_("the robot is bumped (its stall or bumper flags are set)")
    )
    return [
        Reason(
            Cause.STALLED,
            Said(N_("{what} (the server says {words})"), what=Said(what), words=_quote(word)),
            N_(
                "the robot pushed against something or a wheel is blocked: drive away from it, "
                "check the wheels and bumpers"
            ),
            (f"status: {_quote(word)}",),
        )
    ]


def _modes(facts: Facts, motion: Motion | None, navigate: bool) -> list[Reason]:
    out: list[Reason] = []
    info = facts.mode_info
    docked = facts.dock_state == "Docked" or (
        read_status(facts.status).phase is NavOutcome.DOCKED
        and info is not None
        and info.mode_name in DOCK_MODES
    )
    if docked:
        evidence = (
            [f"dockInfo: {facts.dock_state}"] if facts.dock_state else [f"status: {_quote(facts.status)}"]
        )
        fix = (
            Fix("undock", N_("undock (the robot backs out of its dock)"), "undock", False)
            if "undock" in facts.offers
            else None
        )
        out.append(
            Reason(
                Cause.DOCKED,
                N_("the robot is docked (charging)"),
                Said(
                    N_(
                        "undock it first{command}; a drive asks the dock to let go and the robot backs out "
                        "before it drives"
                    ),
                    command=" (undock)" if fix else "",
                ),
                tuple(evidence),
                fix,
            )
        )
    if info is not None and info.locked and not (docked and info.mode_name in DOCK_MODES):
        name = info.mode_name or "(unnamed)"
        said = (
            Said(N_("getModeInfo: mode {mode}, locked, will unlock if asked"), mode=repr(name))
            if info.will_unlock_if_requested
            else Said(N_("getModeInfo: mode {mode}, locked, will not unlock if asked"), mode=repr(name)),
        )
        if info.will_unlock_if_requested:
            fix = _unlock_fix(facts, info)
            out.append(
                Reason(
                    Cause.LOCKED,
                    Said(
                        N_("the {mode} mode holds the robot locked (it will unlock if asked)"),
                        mode=repr(name),
                    ),
                    Said(N_("ask it to unlock: {fix}"), fix=Said(fix.label))
                    if fix
                    else Said(N_("ask it to unlock (this login can send nothing that asks)")),
                    said,
                    fix,
                )
            )
        else:
            out.append(
                Reason(
                    Cause.LOCKED,
                    Said(
                        N_("the {mode} mode holds the robot locked and will not unlock if asked"),
                        mode=repr(name),
                    ),
                    Said(
                        N_(
                            "RTMU cannot release it: whatever locked the {mode} mode (docking, a safety "
                            "mode, a program on the server) must unlock it"
                        ),
                        mode=repr(name),
                    ),
                    said,
                )
            )
    reading = read_status(facts.status, info.mode_name if info else "")
    if reading.phase is NavOutcome.GOING and not docked:
        fix = (
            Fix("stop", N_("send stop (the server's own driving ends)"), "stop", False)
            if "stop" in facts.offers
            else None
        )
        target = f" ({reading.target})" if reading.target else ""
        out.append(
            Reason(
                Cause.NAVIGATING,
                Said(
                    N_("the server is driving the robot itself{target}: {words}"),
                    target=target,
                    words=_quote(reading.text),
                ),
                N_("press STOP first; the next drive is then yours"),
                (f"status: {_quote(reading.text)}",),
                fix,
            )
        )
    if navigate and facts.loc_state == "Lost":
        out.append(
            Reason(
                Cause.LOST,
                N_("the robot is lost (its localization says Lost): it cannot navigate"),
                N_("tell it where it is (rtmu localize, or Set position in the window)"),
                ("getLocState: Lost",),
            )
        )
    return out


def _unlock_fix(facts: Facts, info: ModeInfo) -> Fix | None:
    """Asking means trying to switch modes: ARIA's mode then calls the locked one's requestUnlock.
    A stop switches to the stop mode; when ``stop`` is the locked mode itself, a zero ratioDrive asks."""
    if info.mode_name != "stop" and "stop" in facts.offers:
        return Fix(
            "unlock",
            N_("send stop: switching to the stop mode asks the locked mode to give way"),
            "stop",
            False,
        )
    if "ratioDrive" in facts.offers:
        return Fix(
            "unlock",
            N_(
                "send a zero ratioDrive: switching to the drive mode asks the locked mode to "
                "give way (zero ratios never move the robot)"
            ),
            "ratioDrive",
            False,
        )
    return None


def _watchdog(facts: Facts, motion: Motion | None, navigate: bool) -> list[Reason]:
    t = facts.teleop_timeout
    if t is None or not 0.0 < t < WATCHDOG_MARGIN * RESEND_PERIOD:
        return []
    return [
        Reason(
            Cause.WATCHDOG,
            Said(
                N_(
                    "the server's drive watchdog is {timeout}: shorter than twice the {period} between "
                    "RTMU's drive commands, so it stops the robot between them (jerky motion at best, "
                    "none on a slow link)"
                ),
                timeout=Quantity(t, "s", None),
                period=Quantity(RESEND_PERIOD, "s", None),
            ),
            N_(
                "raise the Teleop Timeout in the server's configuration "
                "(ARIA's default is 2 s; 0 turns it off)"
            ),
            (Said(N_("configuration: Teleop Timeout = {timeout}"), timeout=Quantity(t, "s", None)),),
        )
    ]


_RULES = (
    _our_side,
    _rights,
    _dead_zone,
    _safety_words,
    _battery,
    _stalled,
    _modes,
    _watchdog,
    safe_drive_rule,
)


# -- did it move? ----------------------------------------------------------------------------------
MOVED_MM = 10.0
MOVED_DEG = 2.0


def moved(before: tuple[float, float, float], after: tuple[float, float, float], seen_moving: bool) -> bool:
    """A drive moved the robot: a status during it showed speed, or the pose changed more than the
    odometry's rounding (:data:`MOVED_MM`, :data:`MOVED_DEG`)."""
    (x0, y0, th0), (x1, y1, th1) = before, after
    turned = abs((th1 - th0 + 180.0) % 360.0 - 180.0)
    return seen_moving or math.hypot(x1 - x0, y1 - y0) > MOVED_MM or turned > MOVED_DEG


def unexplained(answer: Answer) -> Answer:
    """A drive that did not move and no cause that explains it: say so rather than exit 0."""
    if any(r.cause is not Cause.NO_STOP for r in answer.reasons):
        return answer
    reason = Reason(
        Cause.UNEXPLAINED,
        N_("the robot did not move, and nothing RTMU can read says why"),
        N_("look at the robot itself (e-stop, motors, faults on its own display) and at the server's log"),
    )
    return Answer((reason, *answer.reasons), answer.notes, answer.raw)

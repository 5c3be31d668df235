"""The words for "why does it not connect": one table shared by ``rtmu doctor`` and the window.

A connection walks through steps (name → TCP → the server's introduction → login → data list →
UDP → first status). Each failure is told as the step it happened at, what went wrong in plain
words, and what to do next. ``rtmu doctor`` prints these step by step; the window's
"Could not connect" banner shows the same sentence (:func:`explain`).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from ..base.i18n import N_, Said, as_said
from ..protocol.commands import RejectReason
from .errors import (
    ClientError,
    ClientTimeout,
    ConnectionFailed,
    ConnectionRefused,
    HostNotFound,
    LoginRejected,
    ProtocolFault,
    ServerClosed,
)


class Step(Enum):
    """The steps of a connection, in order; the value is ``rtmu doctor``'s exit code when it fails."""

    RESOLVE = 10
    TCP = 11
    INTRODUCTION = 12
    LOGIN = 13
    DATA_LIST = 14
    UDP = 16
    """Never fails ``rtmu doctor`` (RTMU uses TCP only)."""
    STATUS = 15
    MOTION = 17
    """Why won't it move (``rtmu why``'s answer): a failing motion step exits with the cause's own
    code (20–39, :class:`rtmu.client.why_values.Cause`), not this value."""

    @property
    def key(self) -> str:
        return self.name.lower()

    @property
    def title(self) -> str:
        return STEP_TITLES[self]


STEP_TITLES = {
    Step.RESOLVE: N_("name resolution"),
    Step.TCP: N_("TCP connection"),
    Step.INTRODUCTION: N_("server introduction"),
    Step.LOGIN: N_("login"),
    Step.DATA_LIST: N_("data list"),
    Step.UDP: N_("UDP"),
    Step.STATUS: N_("first status"),
    Step.MOTION: N_("why won't it move"),
}
"""English, as ``--json`` gives them; marked, and translated where a person reads them."""


@dataclass(frozen=True)
class Finding:
    """One failed step: what happened and what to do about it."""

    step: Step
    problem: str
    advice: str

    def sentence(self) -> str:
        """One line for a banner or a log: "<problem> — <advice>"."""
        if not self.advice:
            return self.problem
        return Said("{problem} — {advice}", problem=as_said(self.problem), advice=as_said(self.advice))


# -- the table ------------------------------------------------------------------------------------
CENTRAL_ADVICE = N_(
    "this is ARIA's central server: use 'rtmu fleet', --robot NAME, or open its robots with 'rtmu --central'"
)
ADVICE = {
    "resolve": N_("check the spelling, or use the robot's IP address instead of its name"),
    "refused": N_(
        "nothing listens on that port: check that the robot's server (ARAM / the ARIA server) "
        "is running and that the port is right (ARIA and Omron LD robots use 7272)"
    ),
    "connect_timeout": N_(
        "no answer at all: the robot may be off, on another network, or a firewall "
        "drops the packets; check that this computer is on the robot's network (try ping)"
    ),
    "unreachable": N_(
        "there is no route to that address: check the network (Wi-Fi, cable, VPN) and the robot's IP address"
    ),
    "not_aria": N_(
        "something answers on that port, but it is not an ARIA robot server: check the port "
        "(ARIA and Omron LD robots use 7272)"
    ),
    "no_introduction": N_(
        "the server accepted the connection but never introduced itself: it may be "
        "busy or hung; restart the robot's server software and try again"
    ),
    "closed_early": N_(
        "the server closed the connection before the login finished: it may be "
        "restarting, or it drops clients it does not like; try again in a minute"
    ),
    "login_timeout": N_("the server did not finish the login in time: it may be overloaded; try again"),
    "status_missing": N_(
        "this server offers no robot status (updateNumbers/update): RTMU can connect "
        "but will show no pose or battery"
    ),
    "central_server": CENTRAL_ADVICE,
    "status_timeout": N_(
        "the server did not send a status in time: the robot's base may be "
        "disconnected from its server; check the robot"
    ),
}


def central_server_words(where: str) -> str:
    """What to do with ARIA's central server, which has no robot of its own (``where``: HOST:PORT)."""
    return (
        f"{where} is ARIA's central server, not a robot: list its robots with 'rtmu fleet {where}', act on "
        f"one with --robot NAME, or open them all with 'rtmu --central {where}'"
    )


REJECT_ADVICE = {
    RejectReason.BAD_USER_OR_PASSWORD: (
        N_("wrong user name or password"),
        N_(
            "check --user and the password (user names are letters and digits only, case-insensitive); "
            "without a user name the server must have no user file"
        ),
    ),
    RejectReason.USING_CENTRAL_SERVER: (
        N_("this robot is managed by a central server"),
        N_("connect to the central server (its address is given above) instead of the robot"),
    ),
    RejectReason.TOO_MANY_CLIENTS: (
        N_("the server has as many clients as it allows"),
        N_("close another client connected to this robot (MobilePlanner, another RTMU), then retry"),
    ),
    RejectReason.CLIENT_TYPE_MISMATCH: (
        N_("the server only accepts clients of another type (real vs simulated robot)"),
        N_("this server is set to refuse clients of RTMU's type; ask its administrator"),
    ),
}


def login_finding(reason: int, text: str = "", wanted: str | None = None, sent: str = "") -> Finding:
    """A REJECTED packet in plain words, with what to do."""
    if reason == RejectReason.PROTOCOL_VERSION_MISMATCH:
        if wanted:
            return Finding(
                Step.LOGIN,
                Said(
                    N_("the server wants protocol {wanted}; we sent {sent}"),
                    wanted=repr(wanted),
                    sent=repr(sent),
                ),
                Said(
                    N_(
                        "use --protocol {wanted} (or leave --protocol out: RTMU then answers with the "
                        "string the server advertises)"
                    ),
                    wanted=wanted,
                ),
            )
        return Finding(
            Step.LOGIN,
            Said(
                N_("the server refuses our protocol string {sent} and does not say which it wants"),
                sent=repr(sent),
            ),
            N_("try --protocol 6MTX (Omron LD robots; older ones 5MTX)"),
        )
    problem: str
    try:
        problem, advice = REJECT_ADVICE[RejectReason(reason)]
    except (ValueError, KeyError):
        problem = Said(N_("the server refused the login (reason {reason})"), reason=reason)
        advice = N_("ask the robot's administrator")
    if text and reason == RejectReason.USING_CENTRAL_SERVER:
        problem = Said(N_("{problem} at {where}"), problem=as_said(problem), where=text)
    elif text and reason not in (RejectReason.TOO_MANY_CLIENTS,):
        problem = Said("{problem} ({text})", problem=as_said(problem), text=text)
    return Finding(Step.LOGIN, problem, advice)


def explain(error: ClientError) -> Finding:
    """The step and the plain words for a failed connection attempt (the window's banner text)."""
    said = error.args[0] if error.args and isinstance(error.args[0], Said) else None
    message: str = said if said is not None else str(error)
    if isinstance(error, HostNotFound):
        return Finding(Step.RESOLVE, message, ADVICE["resolve"])
    if isinstance(error, ConnectionRefused):
        return Finding(Step.TCP, message, ADVICE["refused"])
    if isinstance(error, ClientTimeout):
        if message.startswith("connecting to"):
            return Finding(Step.TCP, message, ADVICE["connect_timeout"])
        return Finding(Step.LOGIN, message, ADVICE["login_timeout"])
    if isinstance(error, ConnectionFailed):
        return Finding(Step.TCP, message, ADVICE["unreachable"])
    if isinstance(error, LoginRejected):
        finding = login_finding(error.reason, error.text, error.wanted_protocol)
        if error.reason == RejectReason.PROTOCOL_VERSION_MISMATCH:  # its message names both strings
            return Finding(Step.LOGIN, message.removeprefix("login refused: "), finding.advice)
        return finding
    if isinstance(error, ProtocolFault):
        return Finding(Step.INTRODUCTION, message, ADVICE["not_aria"])
    if isinstance(error, ServerClosed):
        return Finding(Step.LOGIN, message, ADVICE["closed_early"])
    return Finding(Step.LOGIN, message, "")

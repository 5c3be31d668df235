"""The values of "why won't it move?": causes, reasons with their fixes, the facts read, the answer.

Plain frozen dataclasses with no I/O: :mod:`rtmu.client.why_gather` fills :class:`Facts` from the
server, the window can fill them from what its session already holds, :func:`rtmu.client.why.diagnose`
turns them into an :class:`Answer`, and :mod:`rtmu.client.why_fix` carries out a :class:`Fix`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from typing import Any

from ..base import exit_codes as codes
from ..base.i18n import N_, Said, as_said
from ..protocol.payloads.robot import ModeInfo
from ..values.state import LinkLevel

NOTHING_STOPS_IT = N_("Nothing RTMU can read keeps the robot from moving.")
"""The answer when no reason is found (the window says it in the operator's language)."""


class Cause(Enum):
    """Why a robot does not move; the value is the exit code. Declared in order of precedence:
    the first found is the answer (our own side first, then rights, the robot's safety state, the
    server's modes, and last what only holds it back one way)."""

    LINK = codes.EXIT_WHY_LINK
    LEASE = codes.EXIT_WHY_LEASE
    NO_DRIVE = codes.EXIT_WHY_NO_DRIVE
    DEAD_ZONE = codes.EXIT_WHY_DEAD_ZONE
    ESTOP = codes.EXIT_WHY_ESTOP
    FAULTS = codes.EXIT_WHY_FAULTS
    MOTORS = codes.EXIT_WHY_MOTORS
    BATTERY = codes.EXIT_WHY_BATTERY
    STALLED = codes.EXIT_WHY_STALLED
    DOCKED = codes.EXIT_WHY_DOCKED
    LOCKED = codes.EXIT_WHY_LOCKED
    NAVIGATING = codes.EXIT_WHY_NAVIGATING
    WATCHDOG = codes.EXIT_WHY_WATCHDOG
    SAFE_DRIVE = codes.EXIT_WHY_SAFE_DRIVE
    LOST = codes.EXIT_WHY_LOST
    NO_STOP = codes.EXIT_WHY_NO_STOP
    UNEXPLAINED = codes.EXIT_WHY_UNEXPLAINED

    @property
    def key(self) -> str:
        return self.name.lower()


@dataclass(frozen=True, slots=True)
class Fix:
    """What ``rtmu why --fix`` (or the window's button) may do about a cause."""

    key: str
    """``unlock``, ``undock``, ``stop``, ``safe_drive_off``, ``acknowledge_faults``, ``enable_motors``."""
    label: str
    """What it sends and why, in words."""
    sends: str
    """The data it sends."""
    confirm: bool
    """Needs the operator's explicit yes (it changes how the robot protects itself, or acts on a
    robot whose layouts are not public)."""


@dataclass(frozen=True, slots=True)
class Reason:
    """One cause found: the problem, what to do, and the server data it was read from."""

    cause: Cause
    problem: str
    advice: str
    evidence: tuple[str, ...] = ()
    fix: Fix | None = None
    loud: bool = False
    """A safety fact: shown as a warning whatever else is found."""

    def sentence(self) -> str:
        """ "<problem> — <advice>": English as a ``str`` (``--json``), each part in the operator's language
        through :func:`rtmu.base.i18n.words`."""
        if not self.advice:
            return as_said(self.problem)
        return Said("{problem} — {advice}", problem=as_said(self.problem), advice=as_said(self.advice))

    def as_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "cause": self.cause.key,
            "exit_code": self.cause.value,
            "problem": self.problem,
            "advice": self.advice,
            "evidence": list(self.evidence),
            "loud": self.loud,
        }
        if self.fix is not None:
            out["fix"] = {
                "key": self.fix.key,
                "label": self.fix.label,
                "sends": self.fix.sends,
                "confirm": self.fix.confirm,
            }
        return out


@dataclass(frozen=True, slots=True)
class RawValue:
    """A reply RTMU cannot interpret, shown as it came: the layout is not public."""

    name: str
    description: str
    """The server's own return description from its data list."""
    hex: str
    fields: tuple[str, ...] = ()
    """A best-effort split (strings, or one integer), empty when none fits."""
    note: str = ""
    """Why there is no value (not readable, no reply in time …), "" when there is one."""

    def text(self) -> str:
        if self.note:
            return f"{self.name}: {self.note}"
        shown = ", ".join(self.fields) if self.fields else (self.hex or "(empty)")
        return f"{self.name} (raw, layout not public): {shown}"

    def as_json(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "description": self.description,
            "hex": self.hex,
            "fields": list(self.fields),
            "note": self.note,
        }


@dataclass(frozen=True, slots=True)
class Obstacle:
    """One range reading in the robot's frame: ``x`` mm ahead of the centre, ``y`` mm to the left."""

    x: float
    y: float
    source: str


@dataclass(frozen=True, slots=True)
class SafeDriveLimits:
    """How close safe drive lets the robot come, in mm beyond the footprint's front / rear / sides."""

    front: float
    rear: float
    side: float
    source: str


ARIA_LIMITER_DEFAULTS = SafeDriveLimits(
    150.0, 150.0, 50.0, N_("ARIA's defaults (Clearance 100 + PaddingAtSlowSpeed 50, side 50 mm)")
)
"""ArActionDeceleratingLimiter's defaults, used only when the server does not list its own."""


@dataclass(frozen=True, slots=True)
class Footprint:
    """``physicalInfo``: mm from the centre of rotation."""

    width: float
    front: float
    rear: float

    @property
    def reach(self) -> float:
        """How far ARIA's limiter takes the robot to reach ahead and behind its centre: half its length
        (``ArRobot::getRobotLength() / 2``), whatever the split between front and rear."""
        return (self.front + self.rear) / 2


@dataclass(frozen=True, slots=True)
class OurSide:
    """RTMU's own side of the drive; None / False / "" where not known or not applicable."""

    link: LinkLevel | None = None
    lease_ended: str = ""
    """Why the last drive lease ended (``client.lease.EndReason`` value), "" when live or unknown."""
    keys_blocked: bool = False
    """A key held through a stop is ignored until released (the controller's rule)."""
    replay: bool = False
    guardian: str = ""
    """Why the guardian process is not watching this drive, "" when it is or does not apply."""


@dataclass(frozen=True, slots=True)
class Motion:
    """What the operator asked for (−100…100 %): decides which way an obstacle matters."""

    trans: float = 0.0
    rot: float = 0.0


@dataclass(frozen=True, slots=True)
class Facts:
    """Everything read, from the server (its own data) and from our side. None: not offered or not read."""

    offers: frozenset[str] = frozenset()
    user: str = ""
    status: str = ""
    mode: str = ""
    extended_status: str = ""
    mode_info: ModeInfo | None = None
    safe_drive: bool | None = None
    battery: float | None = None
    battery_shutdown: float | None = None
    battery_soc: bool = False
    vel: float | None = None
    rot_vel: float | None = None
    footprint: Footprint | None = None
    obstacles: tuple[Obstacle, ...] = ()
    sensors: tuple[str, ...] = ()
    """The range devices whose readings were read (an empty ``obstacles`` then means none in range)."""
    limits: SafeDriveLimits | None = None
    dock_state: str | None = None
    loc_state: str | None = None
    teleop_timeout: float | None = None
    faults: tuple[str, ...] | None = None
    """An LD robot's faults as its ``getFaults`` reply reads (strings); None: not listed / unreadable."""
    raw: tuple[RawValue, ...] = ()
    ours: OurSide = field(default_factory=OurSide)
    notes: tuple[str, ...] = ()
    """What could not be read, said plainly (a reply that timed out …)."""


@dataclass(frozen=True, slots=True)
class Answer:
    reasons: tuple[Reason, ...]
    notes: tuple[str, ...] = ()
    raw: tuple[RawValue, ...] = ()

    @property
    def primary(self) -> Reason | None:
        return self.reasons[0] if self.reasons else None

    @property
    def can_move(self) -> bool:
        return not self.reasons

    @property
    def exit_code(self) -> int:
        return self.reasons[0].cause.value if self.reasons else codes.EXIT_OK

    def sentence(self) -> str:
        if not self.reasons:
            return NOTHING_STOPS_IT
        return self.reasons[0].sentence()

    def as_json(self) -> dict[str, Any]:
        p = self.primary
        return {
            "can_move": self.can_move,
            "cause": p.cause.key if p else None,
            "exit_code": self.exit_code,
            "sentence": self.sentence(),
            "reasons": [r.as_json() for r in self.reasons],
            "notes": list(self.notes),
            "raw": [v.as_json() for v in self.raw],
        }

"""Carry out a :class:`~rtmu.client.why_values.Fix`, then watch whether it worked.

Each fix sends one thing and reads back the server's own data until it shows the change (or the
wait ends): ``unlock`` (a stop, or a zero ratioDrive where the stop mode itself is locked: ARIA
asks a locked mode to give way when another mode wants the robot), ``undock``, ``stop`` (ends the
server's own driving), ``safe_drive_off`` (``setSafeDrive`` 0 / ``safeRatioDrivingDisable``),
``acknowledge_faults`` and ``enable_motors`` (an LD robot's; their layouts are not public, so the
argument is built only from the server's own argument description — none, or one string — and
nothing else is ever sent). A fix whose :attr:`~rtmu.client.why_values.Fix.confirm` is set is
sent only when ``confirm(question)`` answers yes: nothing is acknowledged, enabled or made unsafe
behind the operator's back.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from dataclasses import dataclass

from ..protocol.payloads.drive import RatioDrive, SafeDrive, SetSafeDrive
from ..protocol.payloads.ld import DockInfo
from ..protocol.payloads.robot import ModeInfo, UpdateStrings
from ..values.state import NavOutcome
from .connection import AriaClient
from .errors import ClientError
from .nav_status import read_status
from .why_values import Facts, Fix

POLL = 0.1
SETTLE = 10.0
"""At most this long to watch a fix take effect (an undock backs out ~0.6 m first)."""


@dataclass(frozen=True, slots=True)
class FixResult:
    fix: Fix
    sent: bool
    worked: bool
    message: str


Confirm = Callable[[str], bool]


async def apply(
    client: AriaClient, fix: Fix, facts: Facts, confirm: Confirm, timeout: float, settle: float = SETTLE
) -> FixResult:
    """Send ``fix`` (asking ``confirm`` first where it must) and watch for its effect."""
    payloads = _what_to_send(client, fix, facts)
    if isinstance(payloads, str):
        return FixResult(fix, False, False, payloads)
    if fix.confirm:
        shown = "; ".join(_describe(fix.sends, args) for args in payloads)
        if not confirm(f"{fix.label}. RTMU would send: {shown}. Go ahead?"):
            return FixResult(fix, False, False, "not sent: the operator did not confirm")
    try:
        for args in payloads:
            if fix.sends == "ratioDrive":
                client.send(RatioDrive(0.0, 0.0, 0.0))
            elif fix.sends == "setSafeDrive":
                client.send(SetSafeDrive(False))
            else:
                client.send(fix.sends, *args)
        await client.flush()
        worked = await _watch(client, fix, timeout, settle)
    except ClientError as exc:
        return FixResult(fix, True, False, f"sent, but the link failed: {exc}")
    if worked is None:
        return FixResult(fix, True, False, f"sent {fix.sends}; what the robot says now is below")
    if worked:
        return FixResult(fix, True, True, f"sent {fix.sends}: done")
    return FixResult(fix, True, False, f"sent {fix.sends}, but the robot did not change within {settle:g} s")


def _what_to_send(client: AriaClient, fix: Fix, facts: Facts) -> list[tuple[str, ...]] | str:
    """The argument tuples to send (one per packet), or why nothing can be sent."""
    entry = client.datalist.entry(fix.sends)
    if entry is None:
        return f"not sent: this login has no {fix.sends}"
    if fix.key not in ("acknowledge_faults", "enable_motors"):
        return [()]
    arg = entry.argument_description.strip().lower()
    if arg in ("", "none"):
        return [()]
    if fix.key == "acknowledge_faults" and arg.startswith("string") and facts.faults:
        return [(f,) for f in facts.faults]
    return (
        f"not sent: {fix.sends} wants {entry.argument_description!r}, a layout RTMU cannot build "
        "safely; use the robot's own tools"
    )


def _describe(name: str, args: tuple[str, ...]) -> str:
    if name == "ratioDrive":
        return "ratioDrive 0 0 0"
    if name == "setSafeDrive":
        return "setSafeDrive 0"
    return name + "".join(f" {a!r}" for a in args)


async def _watch(client: AriaClient, fix: Fix, timeout: float, settle: float) -> bool | None:
    """True once the server's data shows the fix took effect; None when nothing can show it."""
    check = _CHECKS.get(fix.key)
    if check is None:
        return None
    loop = asyncio.get_running_loop()
    end = loop.time() + settle
    while True:
        state = await check(client, timeout)
        if state is None or state:
            return state
        if loop.time() >= end:
            return False
        await asyncio.sleep(POLL)


async def _reply(client: AriaClient, name: str, timeout: float) -> object | None:
    if not client.supports(name):
        return None
    return (await client.request_once(name, timeout=timeout)).decode()


async def _unlocked(client: AriaClient, timeout: float) -> bool | None:
    info = await _reply(client, "getModeInfo", timeout)
    return None if not isinstance(info, ModeInfo) else not info.locked


async def _undocked(client: AriaClient, timeout: float) -> bool | None:
    dock = await _reply(client, "dockInfo", timeout)
    if isinstance(dock, DockInfo):
        return dock.state_label == "Undocked"
    return await _unlocked(client, timeout)  # ARNL's dock mode holds its lock until it has backed out


async def _not_navigating(client: AriaClient, timeout: float) -> bool | None:
    strings = await _reply(client, "updateStrings", timeout)
    if not isinstance(strings, UpdateStrings):
        return None
    return read_status(strings.status).phase is not NavOutcome.GOING


async def _safe_drive_off(client: AriaClient, timeout: float) -> bool | None:
    safe = await _reply(client, "getSafeDrive", timeout)
    return None if not isinstance(safe, SafeDrive) else not safe.safe


_CHECKS = {
    "unlock": _unlocked,
    "undock": _undocked,
    "stop": _not_navigating,
    "safe_drive_off": _safe_drive_off,
}
"""Acknowledging faults and enabling motors are read back by gathering again (their layouts are
not public: the new answer is what tells)."""

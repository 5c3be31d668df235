"""``rtmu why HOST[:PORT] [--json] [--fix] [--yes] [--navigate]``: why won't the robot move?

Plain words for the help (:data:`DESCRIPTION`); the answer itself is :mod:`rtmu.client.why`'s, its
exit code the cause's own (``rtmu.base.exit_codes``, :data:`rtmu.base.exit_codes.WHY_ASKED`).
Without ``--fix`` this is an observer (its client cannot send a motion request); ``--fix`` logs in
as an operator, because unlocking a mode or stopping the server's own driving sends ``stop``.
"""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_WHY_LOST, NETWORK, WHY_ASKED
from ..base.i18n import N_, _, words
from ..base.textsafe import visible
from ..client.roles import Role
from ._common import add_connection_arguments, print_json, run_with_client

if TYPE_CHECKING:
    from ..client.connection import AriaClient
    from ..client.why_fix import FixResult
    from ..client.why_values import Answer

EXITS = (*NETWORK, *WHY_ASKED, EXIT_WHY_LOST)
MAX_FIXES = 3
"""Fixes tried one after another (each reveals what the next cause is)."""
DESCRIPTION = N_("""Why won't the robot move? Reads, never drives: the server's own data (its mode and lock,
this login's rights, status words, safe drive and the obstacles its sonar and lasers see, battery,
docking, localization, its drive watchdog, an LD robot's faults and safety data), told as one sentence
with its fix. Exit 0 when nothing RTMU can read keeps the robot from moving, else the cause's own code
(listed below): 20 this login may not stop, 21 may not drive, 23 e-stop, 24 faults, 25 motors disabled,
26 stalled, 27 mode locked, 28 navigating, 29 docked, 30 battery, 31 safe drive, 32 drive watchdog,
33 lost (with --navigate).

--fix carries out the first cause's fix where there is one (unlock a mode that will unlock, undock, stop
the server's own driving, switch safe drive off, acknowledge an LD robot's faults, enable its motors),
then asks again. Switching safe drive off, acknowledging and enabling need a yes: typed at the prompt, or
--yes; without one nothing is sent.""")


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "why",
        help=_("why won't the robot move? one sentence and its fix"),
        description=_(DESCRIPTION),
    )
    add_connection_arguments(p)
    p.add_argument(
        "--json", action="store_true", help=_("one JSON object: the answer, its reasons and fixes")
    )
    p.add_argument(
        "--fix", action="store_true", help=_("carry out the fix where there is one, then ask again")
    )
    p.add_argument(
        "--yes", action="store_true", help=_("confirm fixes that need a yes (safe drive off, LD faults)")
    )
    p.add_argument("--navigate", action="store_true", help=_("ask about navigation (a lost robot counts)"))
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..client.why import diagnose
    from ..client.why_gather import gather

    async def body(client: AriaClient) -> int:
        answer = diagnose(await gather(client, args.timeout), navigate=args.navigate)
        results: list[FixResult] = []
        if args.fix:
            answer, results = await fix_all(client, answer, args)
        if args.json:
            print_json(
                {
                    "server": "{}:{}".format(*args.server),
                    **answer.as_json(),
                    "fixes": [fix_json(r) for r in results],
                }
            )
        else:
            for r in results:
                print(
                    _("fix: {visible}: {visible2}").format(
                        visible=visible(r.fix.label), visible2=visible(r.message)
                    )
                )
            print_answer(answer)
        return answer.exit_code

    # Asking never moves anything; --fix may send a stop (unlocking a mode) or switch safe drive.
    role = Role.OPERATOR if getattr(args, "fix", False) else Role.OBSERVER
    return run_with_client("why", args, body, role=role)


async def fix_all(
    client: AriaClient, answer: Answer, args: argparse.Namespace
) -> tuple[Answer, list[FixResult]]:
    from ..client.why import diagnose
    from ..client.why_fix import apply
    from ..client.why_gather import gather

    results: list[FixResult] = []
    tried: set[str] = set()
    for _attempt in range(MAX_FIXES):
        reason = next((r for r in answer.reasons if r.fix is not None and r.fix.key not in tried), None)
        if reason is None or reason.fix is None:
            break
        tried.add(reason.fix.key)
        facts = await gather(client, args.timeout)
        result = await apply(client, reason.fix, facts, lambda q: confirm(q, args.yes), args.timeout)
        results.append(result)
        answer = diagnose(await gather(client, args.timeout), navigate=args.navigate)
        if not result.sent:
            break
    return answer, results


def confirm(question: str, yes: bool) -> bool:
    """The operator's explicit yes: ``--yes``, or "y" typed at a terminal; anything else is no."""
    if yes:
        return True
    if not sys.stdin.isatty():
        print(
            _("rtmu: {visible} — not confirmed (no terminal to ask; add --yes)").format(
                visible=visible(question)
            ),
            file=sys.stderr,
        )
        return False
    try:
        said = input(f"{visible(question)} [y/N] ")
    except EOFError:
        return False
    return said.strip().lower() in ("y", "yes")


def fix_json(r: FixResult) -> dict[str, Any]:
    return {"key": r.fix.key, "sent": r.sent, "worked": r.worked, "message": r.message}


def print_answer(answer: Answer, out: Any = None, lead: str = "") -> None:
    """The answer in words: the sentence, what to do, where it came from; warnings; raw values."""
    out = out or sys.stdout
    p = answer.primary
    if p is None:
        print(lead + words(answer.sentence()), file=out)
    else:
        print(f"{lead}{visible(words(p.problem))}", file=out)
        print(_("  what to do: {visible}").format(visible=visible(words(p.advice))), file=out)
        if p.fix is not None:
            can = _("  rtmu why --fix can: {fix}").format(fix=visible(words(p.fix.label)))
            print(can + (_(" (asks first)") if p.fix.confirm else ""), file=out)
        for e in p.evidence:
            print(_("  from: {visible}").format(visible=visible(words(e))), file=out)
    for r in answer.reasons[1:]:
        mark = _("WARNING") if r.loud else _("also")
        print(f"{mark}: {visible(words(r.sentence()))}", file=out)
    for note in answer.notes:
        print(_("note: {visible}").format(visible=visible(words(note))), file=out)
    for v in answer.raw:
        print(_("raw: {visible}").format(visible=visible(v.text())), file=out)

"""``rtmu goto HOST[:PORT] GOAL`` or ``--x MM --y MM [--th DEG]``: send the robot there and follow it.

Which command goes out (see ``--help``): ARNL's ``gotoGoal`` / ``gotoPose`` wherever the server lists
them — the server then reports ``Going to …`` / ``Arrived at …`` and we wait for the outcome. An LD
robot that lists ``gotoRouteGoal`` but not ``gotoGoal`` (or ``--route``) gets ``gotoRouteGoal``, and
the command ends once it is sent, as before: those robots report progress elsewhere.
"""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_OK, EXIT_USAGE
from ..base.i18n import N_, _
from ..base.textsafe import visible
from ..client.roles import Role
from ._common import UsageError, add_connection_arguments, known_name, run_with_client
from ._nav_args import NAVIGATION_EXITS, add_wait_arguments, require

if TYPE_CHECKING:
    from ..client.connection import AriaClient

RULE = N_(
    "GOAL goes as ARNL's gotoGoal wherever the server lists it, and the command follows the robot to "
    "the end; a server with gotoRouteGoal but no gotoGoal (Omron LD robots), or --route, gets "
    "gotoRouteGoal instead and the command ends once it is sent. --x/--y go as gotoPose. The goal "
    "must be one getGoals lists (exit 2 otherwise; rtmu goals lists them)."
)


EXITS = NAVIGATION_EXITS


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "goto",
        help=_("drive to a goal of the map or to a point (gotoGoal / gotoPose; LD robots: gotoRouteGoal)"),
        description=_(RULE) + " " + _("Ctrl-C, SIGTERM and SIGHUP stop the robot."),
    )
    add_connection_arguments(p)
    p.add_argument("goal", metavar="GOAL", nargs="?", help=_("goal name, as the map names it"))
    p.add_argument("--x", type=float, metavar="MM", help=_("drive to this point instead (map mm)"))
    p.add_argument("--y", type=float, metavar="MM", help=_("the point's y (map mm)"))
    p.add_argument("--th", type=float, metavar="DEG", help=_("and end facing this heading (degrees)"))
    p.add_argument("--route", action="store_true", help=_("send gotoRouteGoal even where gotoGoal is listed"))
    add_wait_arguments(p)
    p.set_defaults(handler=handle)


def check(args: argparse.Namespace) -> None:
    point = args.x is not None or args.y is not None or args.th is not None
    if args.goal is not None and point:
        raise UsageError(_("give either GOAL or --x/--y, not both"))
    if args.goal is None and (args.x is None or args.y is None):
        raise UsageError(_("give a GOAL, or a point with --x MM --y MM [--th DEG]"))
    if point and args.route:
        raise UsageError(_("--route takes a GOAL, not a point"))


def handle(args: argparse.Namespace) -> int:
    from ..client import ld_data
    from ..protocol.payloads.navigation import GotoGoal, GotoPose
    from ._navigate import Expect, navigate

    try:
        check(args)
    except UsageError as exc:
        print(_("rtmu goto: {exc}").format(exc=exc), file=sys.stderr)
        return EXIT_USAGE

    async def body(client: AriaClient) -> int:
        if args.goal is None:
            require(client, "gotoPose", N_("this server does not drive to points (it does not offer {name})"))
            th = None if args.th is None else round(args.th)
            return await navigate(client, args, GotoPose(round(args.x), round(args.y), th), Expect("point"))
        route = args.route or (not client.supports("gotoGoal") and client.supports("gotoRouteGoal"))
        if route:
            # exit 4 before asking for goals
            require(
                client,
                "gotoRouteGoal",
                N_("this server does not drive to route goals (it does not offer {name})"),
            )
        else:
            require(client, "gotoGoal", N_("this server does not drive to goals (it does not offer {name})"))
        if client.supports("getGoals"):
            known = await ld_data.goals(client, args.timeout)
            goal = known_name("goto", "goal", args.goal, known)
            if goal is None:
                return EXIT_USAGE
            args.goal = goal  # as the map spells it: what the server's words will name
        if route:
            ld_data.goto_route_goal(client, args.goal)
            print(_("going to {visible}").format(visible=visible(args.goal)), file=sys.stderr)
            return EXIT_OK
        return await navigate(client, args, GotoGoal(args.goal), Expect(args.goal))

    return run_with_client("goto", args, body, role=Role.OPERATOR)

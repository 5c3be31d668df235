"""``rtmu goto HOST[:PORT] GOAL``: send the robot to one of the map's goals (``gotoRouteGoal``, LD robots)."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from ..client import ld_data
from ..client.connection import AriaClient
from ..exit_codes import EXIT_OK, EXIT_USAGE
from ..textsafe import visible
from ._common import add_connection_arguments, run_with_client, unknown_name


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "goto",
        help="drive to one of the map's goals (LD robots: gotoRouteGoal)",
        description="Send gotoRouteGoal GOAL; the goal must be one getGoals lists (exit 2 otherwise). "
        "The robot then drives by itself: `rtmu drive … --seconds 0` or the window's STOP stops it.",
    )
    add_connection_arguments(p)
    p.add_argument("goal", metavar="GOAL", help="goal name, as the map names it")
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    async def body(client: AriaClient) -> int:
        if not client.supports("gotoRouteGoal"):  # say so before asking for goals
            ld_data.goto_route_goal(client, args.goal)  # raises NotSupported (exit 4)
        known = await ld_data.goals(client, args.timeout)
        if unknown_name("goto", "goal", args.goal, known):
            return EXIT_USAGE
        ld_data.goto_route_goal(client, args.goal)
        print(f"going to {visible(args.goal)}", file=sys.stderr)
        return EXIT_OK

    return run_with_client("goto", args, body)

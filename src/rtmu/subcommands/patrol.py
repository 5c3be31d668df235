"""``rtmu patrol HOST[:PORT] ROUTE``: start patrolling one of the server's routes (LD robots)."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from ..base.exit_codes import EXIT_OK, EXIT_USAGE
from ..base.textsafe import visible
from ..client import ld_data
from ..client.connection import AriaClient
from ..client.roles import Role
from ._common import add_connection_arguments, known_name, run_with_client


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "patrol",
        help="patrol one of the server's routes (LD robots)",
        description="Send patrol ROUTE; the route must be one getRoutes lists (exit 2 otherwise).",
    )
    add_connection_arguments(p)
    p.add_argument("route", metavar="ROUTE", help="route name, as `rtmu routes` lists it")
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    async def body(client: AriaClient) -> int:
        known = await ld_data.routes(client, args.timeout)
        route = known_name("patrol", "route", args.route, known)
        if route is None:
            return EXIT_USAGE
        args.route = route
        ld_data.patrol(client, args.route)
        print(f"patrolling {visible(args.route)}", file=sys.stderr)
        return EXIT_OK

    return run_with_client("patrol", args, body, role=Role.OPERATOR)

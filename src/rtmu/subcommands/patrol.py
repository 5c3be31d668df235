"""``rtmu patrol HOST[:PORT] ROUTE``: start patrolling one of the server's routes (LD robots)."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_OK, EXIT_USAGE
from ..base.i18n import _
from ..base.textsafe import visible
from ..client.roles import Role
from ._common import add_connection_arguments, known_name, run_with_client

if TYPE_CHECKING:
    from ..client.connection import AriaClient


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "patrol",
        help=_("patrol one of the server's routes (LD robots)"),
        description=_("Send patrol ROUTE; the route must be one getRoutes lists (exit 2 otherwise)."),
    )
    add_connection_arguments(p)
    p.add_argument("route", metavar="ROUTE", help=_("route name, as `rtmu routes` lists it"))
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..client import ld_data

    async def body(client: AriaClient) -> int:
        known = await ld_data.routes(client, args.timeout)
        route = known_name("patrol", "route", args.route, known)
        if route is None:
            return EXIT_USAGE
        args.route = route
        ld_data.patrol(client, args.route)
        print(_("patrolling {visible}").format(visible=visible(args.route)), file=sys.stderr)
        return EXIT_OK

    return run_with_client("patrol", args, body, role=Role.OPERATOR)

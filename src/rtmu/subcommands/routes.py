"""``rtmu routes HOST[:PORT]``: list the routes an LD (ARAM) server offers (``getRoutes``)."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_OK
from ..base.i18n import _
from ..base.textsafe import visible
from ..client.roles import Role
from ._common import add_connection_arguments, print_json, run_with_client

if TYPE_CHECKING:
    from ..client.connection import AriaClient


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "routes",
        help=_("list the server's routes (LD robots)"),
        description=_("List the routes the server offers (getRoutes), one per line; exit 4 if it has none."),
    )
    add_connection_arguments(p)
    p.add_argument("--json", action="store_true", help=_("a JSON list of route names"))
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..client import ld_data

    async def body(client: AriaClient) -> int:
        names = await ld_data.routes(client, args.timeout)
        if args.json:
            print_json(list(names))
        else:
            for name in names:
                print(visible(name))
        return EXIT_OK

    return run_with_client("routes", args, body, role=Role.OBSERVER)

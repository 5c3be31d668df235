"""``rtmu goals HOST[:PORT] [--json]``: the map's goal names, as the server lists them (``getGoals``)."""

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
        "goals",
        help=_("list the map's goals (getGoals), the names rtmu goto takes"),
        description=_("Print the goal names getGoals lists, one a line (exit 4 when the server lists none)."),
    )
    add_connection_arguments(p)
    p.add_argument("--json", action="store_true", help=_("one JSON array of names"))
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..client import ld_data

    async def body(client: AriaClient) -> int:
        names = await ld_data.goals(client, args.timeout)  # NotSupported (exit 4) without getGoals
        if args.json:
            print_json(list(names))
        else:
            for name in names:
                print(visible(name), flush=True)
        return EXIT_OK

    return run_with_client("goals", args, body, role=Role.OBSERVER)

"""``rtmu commands HOST[:PORT] [--json]``: the server's own commands this user may run (§4.10)."""

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
        "commands",
        help=_("list the server's own commands (listCommands, listStringCommands) this user may run"),
        description=_(
            "Print each command the server lists and this user may run, with its description; "
            "ARG marks a command that takes one text argument (rtmu run NAME ARG). Exit 4 when the server "
            "lists none."
        ),
    )
    add_connection_arguments(p)
    p.add_argument("--json", action="store_true", help=_("one JSON array of {name, description, argument}"))
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..client.custom_commands import list_commands

    async def body(client: AriaClient) -> int:
        catalogue = await list_commands(client, args.timeout)  # NotSupported (exit 4) without a list
        if args.json:
            print_json(
                [
                    {"name": c.name, "description": c.description, "argument": c.takes_argument}
                    for c in catalogue.commands
                ]
            )
            return EXIT_OK
        width = max((len(visible(c.name)) for c in catalogue.commands), default=0)
        for c in catalogue.commands:
            arg = "ARG" if c.takes_argument else "   "
            # A description may span lines (ARIA's MicroControllerCommand does): one line each here.
            print(f"{visible(c.name):<{width}}  {arg}  {visible(c.description)}", flush=True)
        return EXIT_OK

    return run_with_client("commands", args, body, role=Role.OBSERVER)

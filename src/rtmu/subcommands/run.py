"""``rtmu run HOST[:PORT] NAME [ARG]``: run one of the server's own commands and see that it was taken.

ARIA's commands have no reply. After sending, ``run`` asks the server for something cheap: since a
server handles one client's packets in order, its answer proves the command was taken. Exit codes:
0 taken, 2 usage (a command this user may not run or the server does not list, a missing or
unexpected ARG), 3 connection, 4 the server lists no commands, 5 sent but the server stayed silent
for ``--timeout`` s.
"""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_OK, EXIT_TIMEOUT, EXIT_USAGE
from ..base.i18n import _
from ..base.textsafe import visible
from ..client.roles import Role
from ._common import add_connection_arguments, known_name, print_json, run_with_client

if TYPE_CHECKING:
    from ..client.connection import AriaClient


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "run",
        help=_("run one of the server's own commands (rtmu commands lists them)"),
        description=_(
            "Send the listed command NAME (with ARG for a string command) and wait until the "
            "server has taken it. Exit 0 taken, 2 not a command this user may run or a wrong ARG, 4 the "
            "server lists no commands, 5 no answer within --timeout."
        ),
    )
    add_connection_arguments(p)
    p.add_argument("name", metavar="NAME", help=_("the command's name, as rtmu commands prints it"))
    p.add_argument("argument", metavar="ARG", nargs="?", help=_("the text argument of a string command"))
    p.add_argument("--json", action="store_true", help=_("one JSON object {command, argument, taken}"))
    p.set_defaults(handler=handle)


def usage(message: str) -> int:
    print(_("rtmu run: {visible}").format(visible=visible(message)), file=sys.stderr)
    return EXIT_USAGE


def handle(args: argparse.Namespace) -> int:
    from ..client.custom_commands import MAX_ARGUMENT, list_commands, run_command

    if args.argument is not None and len(args.argument) > MAX_ARGUMENT:
        return usage(f"ARG is longer than {MAX_ARGUMENT} characters")

    async def body(client: AriaClient) -> int:
        catalogue = await list_commands(client, args.timeout)  # NotSupported (exit 4) without a list
        names = tuple(c.name for c in catalogue.commands)
        name = known_name("run", "command", args.name, names)
        if name is None:
            return EXIT_USAGE
        args.name = name
        command = catalogue.find(args.name)
        assert command is not None
        if command.takes_argument and args.argument is None:
            return usage(f"{args.name} takes an argument: rtmu run HOST {args.name} ARG")
        if not command.takes_argument and args.argument is not None:
            return usage(f"{args.name} takes no argument")
        taken = await run_command(client, command, args.argument, args.timeout)
        if args.json:
            print_json({"command": command.name, "argument": args.argument, "taken": taken})
        elif taken:
            print(_("{visible}: taken by the server").format(visible=visible(command.name)), flush=True)
        else:
            silent = f"sent, but the server did not answer within {args.timeout:g} s"
            print(
                _("rtmu run: {visible} {silent}").format(visible=visible(command.name), silent=silent),
                file=sys.stderr,
            )
        return EXIT_OK if taken else EXIT_TIMEOUT

    return run_with_client("run", args, body, role=Role.OPERATOR)

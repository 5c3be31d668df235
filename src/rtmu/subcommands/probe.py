"""``rtmu probe HOST[:PORT]``: log in and list what the server offers, like ARIA's clientCommandLister."""

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
        "probe",
        help=_("log in and list the data a server offers"),
        description=_(
            "Log in and list every data the server offers this user: number, name, group, "
            "flags, description, argument and return descriptions."
        ),
    )
    add_connection_arguments(p)
    p.add_argument(
        "--json",
        action="store_true",
        help=_(
            'one JSON object: {"server", "user", "count", "data": [{"number", "name", "group", '
            '"flags", "description", "arguments", "returns"}]}'
        ),
    )
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    async def body(client: AriaClient) -> int:
        entries = list(client.datalist)
        host, port = args.server
        if args.json:
            print_json(
                {
                    "server": f"{host}:{port}",
                    "user": args.user,
                    "count": len(entries),
                    "data": [
                        {
                            "number": e.number,
                            "name": e.name,
                            "group": e.command_group,
                            "flags": sorted(e.flag_set),
                            "description": e.description,
                            "arguments": e.argument_description,
                            "returns": e.return_description,
                        }
                        for e in entries
                    ],
                }
            )
            return EXIT_OK
        print(
            f"{host}:{port} offers {len(entries)} data" + (f" to {visible(args.user)}" if args.user else "")
        )
        groups: dict[str, list[Any]] = {}
        for e in entries:
            groups.setdefault(e.command_group or "(no group)", []).append(e)
        for group in sorted(groups):
            print(f"\n{visible(group)}:")
            for e in groups[group]:
                print(f"  {e.number:5d}  {visible(e.name)}  [{visible(e.flags)}]")
                if e.description:
                    print(f"         {visible(e.description)}")
                if e.argument_description and e.argument_description.lower() not in ("none", ""):
                    print(_("         args:    {visible}").format(visible=visible(e.argument_description)))
                if e.return_description and e.return_description.lower() not in ("none", ""):
                    print(_("         returns: {visible}").format(visible=visible(e.return_description)))
        return EXIT_OK

    return run_with_client("probe", args, body, role=Role.OBSERVER)

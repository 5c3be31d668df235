"""``rtmu localize HOST[:PORT] X Y TH``: tell the server where the robot is (``localizeToPose``)."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import NETWORK
from ..base.i18n import N_, _
from ..client.roles import Role
from ._common import add_connection_arguments, run_with_client
from ._nav_args import EXIT_NAV_LOST, add_wait_arguments, require

if TYPE_CHECKING:
    from ..client.connection import AriaClient

EXITS = (*NETWORK, EXIT_NAV_LOST)


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "localize",
        help=_("tell the robot where it is on the map (localizeToPose), and wait until it is localized"),
        description=_(
            "Send localizeToPose X Y TH; where the server offers getLocState, wait until it says "
            "localized (exit 0; also when it was only sent, where getLocState is not offered) or lost "
            "(exit {code}). It never moves the robot."
        ).format(code=EXIT_NAV_LOST),
    )
    add_connection_arguments(p)
    p.add_argument("x", type=float, metavar="X", help=_("mm on the map"))
    p.add_argument("y", type=float, metavar="Y", help=_("mm on the map"))
    p.add_argument("th", type=float, metavar="TH", help=_("heading, degrees (counter-clockwise)"))
    add_wait_arguments(p, localizing=True)
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..protocol.payloads.navigation import LocalizeToPose
    from ._navigate import localize

    async def body(client: AriaClient) -> int:
        require(
            client,
            "localizeToPose",
            N_("this server does not take a pose to localize at (it does not offer {name})"),
        )
        return await localize(client, args, LocalizeToPose(round(args.x), round(args.y), round(args.th)))

    return run_with_client("localize", args, body, role=Role.OPERATOR)

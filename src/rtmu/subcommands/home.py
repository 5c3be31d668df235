"""``rtmu home HOST[:PORT]``: send the robot home (ARNL's ``home``) and follow it until it is there."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, Any

from ..base.i18n import N_, _
from ..client.roles import Role
from ._common import add_connection_arguments, run_with_client
from ._nav_args import NAVIGATION_EXITS, add_wait_arguments, require

if TYPE_CHECKING:
    from ..client.connection import AriaClient

EXITS = NAVIGATION_EXITS


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "home",
        help=_("drive home (ARNL: home), and wait until the robot is there"),
        description=_(
            "Send home: the server drives to the map's home (or where the robot started) and says "
            "'Returned home'. Ctrl-C, SIGTERM and SIGHUP stop the robot."
        ),
    )
    add_connection_arguments(p)
    add_wait_arguments(p)
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..protocol.payloads.navigation import Home
    from ._navigate import Expect, navigate

    async def body(client: AriaClient) -> int:
        require(client, "home", N_("this server does not drive home (it does not offer {name})"))
        return await navigate(client, args, Home(), Expect("home"))

    return run_with_client("home", args, body, role=Role.OPERATOR)

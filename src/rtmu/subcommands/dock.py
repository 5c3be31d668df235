"""``rtmu dock HOST[:PORT]``: send the robot to its charger (``dock``) and follow it until docked."""

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
        "dock",
        help=_("drive to the charger and dock (dock), and wait until docked"),
        description=_(
            "Send dock: the server drives to its dock and says 'Docked' (LD robots: dockInfo says "
            "Docked). A drive command undocks again. Ctrl-C, SIGTERM and SIGHUP stop the robot."
        ),
    )
    add_connection_arguments(p)
    add_wait_arguments(p)
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..protocol.payloads.navigation import Dock
    from ._navigate import Expect, navigate

    async def body(client: AriaClient) -> int:
        require(client, "dock", N_("this server does not dock (it does not offer {name})"))
        return await navigate(client, args, Dock(), Expect(docked=True))

    return run_with_client("dock", args, body, role=Role.OPERATOR)

"""``rtmu fleet HOST[:PORT]``: the robots behind an ARIA central server, with a status line each.

The central server (ARIA's ``switchServer``, or ``rtmu sim --central``) lists its robots and the port
it forwards each on; this asks for the list, then reads one status from every robot through its
forwarded port (at the same time, each within ``--timeout``). ``--json`` prints one object:
``{"central": "HOST:PORT", "robots": [{"name", "host", "port", "address", "status"}]}`` where
``status`` is the object ``rtmu status --json`` prints, or ``{"error": "..."}`` for a robot that did
not answer. Act on one of them with any subcommand's ``--robot NAME``.
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_CONNECTION, EXIT_OK, EXIT_USAGE
from ..base.i18n import _, ngettext
from ..base.textsafe import visible
from ..client.errors import ClientError
from ..client.roles import Role
from ..protocol.errors import ProtocolError
from ..values.target import Target
from ._common import (
    Interrupted,
    UsageError,
    add_connection_arguments,
    fail,
    print_json,
    read_password,
    run_interruptibly,
)
from ._status import fetch_status, status_line

if TYPE_CHECKING:
    import asyncio

MAX_AT_ONCE = 16
"""Robots asked for their status at the same time (a central server may forward hundreds)."""


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "fleet",
        help=_("list the robots behind an ARIA central server, with their status"),
        description=_(
            "Ask an ARIA central server (ARIA's switchServer, or rtmu sim --central) for its "
            "robots and the port it forwards each on, then read one status from every robot through that "
            "port (all at once, each within --timeout). --json prints one object: "
            '{"central": "HOST:PORT", "robots": [{"name", "host", "port", "address", "status"}]} where '
            'status is what rtmu status --json prints, or {"error": "..."} for a robot that did not answer. '
            "Act on one of them with any other subcommand's --robot NAME."
        ),
    )
    add_connection_arguments(p, robot=False)  # it lists every robot: no --robot NAME
    p.add_argument("--json", action="store_true", help=_("one JSON object (see above)"))
    p.add_argument("--no-status", action="store_true", help=_("list only; do not log in to each robot"))
    p.set_defaults(handler=handle)


async def _status(
    host: str, port: int, args: argparse.Namespace, password: str, gate: asyncio.Semaphore
) -> dict[str, Any]:
    from ..client.connection import AriaClient

    async with gate:
        client = AriaClient()
        try:
            target = Target(host, port, args.user, password, protocol=args.protocol)
            await client.connect(target, timeout=args.timeout, role=Role.OBSERVER)
            return await fetch_status(client, args.timeout)
        except (ClientError, ProtocolError) as exc:
            return {"error": str(exc)}
        finally:
            await client.disconnect()


def handle(args: argparse.Namespace) -> int:
    import asyncio

    from ..client.central import list_robots, one_per_name

    try:
        password = read_password(args)
    except UsageError as exc:
        return fail("fleet", str(exc), EXIT_USAGE)
    except (KeyboardInterrupt, EOFError):
        return fail("fleet", "cancelled", EXIT_USAGE)
    host, port = args.server

    async def main() -> list[dict[str, Any]]:
        robots = one_per_name(await list_robots(host, port, args.user, password, timeout=args.timeout))
        gate = asyncio.Semaphore(MAX_AT_ONCE)
        statuses: list[dict[str, Any] | None] = [None] * len(robots)
        if not args.no_status:
            statuses = list(
                await asyncio.gather(*(_status(e.host, e.port, args, password, gate) for e, _count in robots))
            )
        rows = []
        for (endpoint, entry), status in zip(robots, statuses, strict=True):
            row: dict[str, Any] = {
                "name": endpoint.name,
                "host": endpoint.host,
                "port": endpoint.port,
                "address": entry.address,
            }
            if status is not None:
                row["status"] = status
            rows.append(row)
        return rows

    try:
        rows = run_interruptibly(main)
    except Interrupted as exc:
        return fail("fleet", str(exc), exc.exit_code)
    except ClientError as exc:
        return fail("fleet", str(exc), exc.exit_code)
    except ProtocolError as exc:
        return fail("fleet", f"the central server sent a malformed robot list: {exc}", EXIT_CONNECTION)
    if args.json:
        print_json({"central": f"{host}:{port}", "robots": rows})
        return EXIT_OK
    print(
        ngettext("{host}:{port}: {count} robot", "{host}:{port}: {count} robots", len(rows)).format(
            host=host, port=port, count=len(rows)
        )
    )
    for row in rows:
        status = row.get("status")
        shown = "" if status is None else status.get("error") or status_line(status)
        print(
            _("  {visible}  port {value}  {visible2}").format(
                visible=visible(row["name"]), value=row["port"], visible2=visible(shown)
            ),
            flush=True,
        )
    return EXIT_OK


handle.resolves_robot = True  # type: ignore[attr-defined]  # --robot is refused here, not resolved

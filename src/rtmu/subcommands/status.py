"""``rtmu status HOST[:PORT]``: print the robot's status once, or stream it.

``--json`` prints one JSON object per status (one line each when streaming) with
the keys ``x``, ``y`` (mm), ``th`` (degrees), ``vel`` (mm/s), ``rot_vel``
(deg/s), ``battery_v`` (volts) — or ``battery_pct`` instead when the robot
reports state of charge (``batteryInfo``) — ``status`` and ``mode``, and ``dock`` (Undocked,
Docking, Docked, Undocking) when the server offers ``dockInfo`` (LD robots).
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_OK
from ..base.i18n import _
from ..base.units import quantity
from ..client.errors import ClientTimeout, ProtocolFault
from ..client.roles import Role
from ..protocol.errors import ProtocolError
from ..protocol.payloads.ld import DockInfo
from ..protocol.payloads.robot import Update, UpdateNumbers, UpdateStrings
from ._common import (
    add_connection_arguments,
    print_json,
    run_with_client,
)
from ._options import number_in
from ._status import fetch_status, status_line, status_object

if TYPE_CHECKING:
    import asyncio

    from ..client.call_values import Packet
    from ..client.connection import AriaClient

HEARTBEAT = 1.0
"""Seconds: an unchanged status is printed again this often, so a reader knows the link is alive."""


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "status",
        help=_("print or stream the robot status"),
        description=_(
            "Print the robot status once (--once) or stream it until interrupted: a line whenever "
            "the status changes, and the same line again at most every {heartbeat} s while it does not "
            "(a heartbeat: the link is alive). JSON keys (schema status): x, y (mm), th (deg), vel (mm/s), "
            "rot_vel (deg/s), battery_v (volts) or battery_pct (state of charge), status, mode, and dock "
            "where the server offers dockInfo."
        ).format(heartbeat=f"{HEARTBEAT:g}"),
    )
    add_connection_arguments(p)
    p.add_argument("--once", action="store_true", help=_("print one status and exit"))
    p.add_argument("--json", action="store_true", help=_("JSON: one object (one per line when streaming)"))
    p.add_argument(
        "--interval",
        type=number_in(10, 60_000, integer=True),
        default=100,
        metavar="MS",
        help=_("how often the server is asked for the status when streaming, 10…60000 ms (default 100)"),
    )
    p.add_argument(
        "--count",
        type=number_in(0, 1e9, integer=True),
        default=0,
        metavar="N",
        help=_("stop after N lines (default 0: never)"),
    )
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..client import ld_data

    def show(obj: dict[str, Any]) -> None:
        if args.json:
            print_json(obj)
        else:
            dock = f"  dock={obj['dock']}" if "dock" in obj else ""
            print(status_line(obj) + dock, flush=True)

    async def body(client: AriaClient) -> int:
        if args.once:
            obj = await fetch_status(client, args.timeout)
            dock = await ld_data.dock_info(client, args.timeout)
            show(obj if dock is None else {**obj, "dock": dock.state_label})
            return EXIT_OK
        return await stream(client, args, show)

    return run_with_client("status", args, body, role=Role.OBSERVER)


def say(message: str) -> None:
    """A note for the operator on stderr, apart from the status lines (or JSON) on stdout."""
    print(_("rtmu status: {message}").format(message=message), file=sys.stderr, flush=True)


async def stream(client: AriaClient, args: argparse.Namespace, show: Any) -> int:
    import asyncio
    from dataclasses import replace

    from ..client import ld_data
    from ..client.robot_status import battery_fields, battery_info, no_status, numbers_fields, strings_fields
    from ..values.state import RobotState

    info = await battery_info(client, args.timeout)
    robot = [RobotState() if info is None else RobotState(**battery_fields(info))]
    """The status so far, read as the window reads it; each numbers packet prints it."""
    dock: dict[str, str] = {}
    """``{"dock": label}`` when the server offers dockInfo, kept current by dockInfoChanged."""
    first_dock = await ld_data.dock_info(client, args.timeout)
    if first_dock is not None:
        dock["dock"] = first_dock.state_label

    def on_dock(packet: Packet) -> None:
        with contextlib.suppress(ProtocolError):
            d = packet.decode()
            if isinstance(d, DockInfo):
                dock["dock"] = d.state_label

    if first_dock is not None and client.supports("dockInfoChanged"):
        client.request("dockInfoChanged", -1, on_dock)
    queue: asyncio.Queue[dict[str, Any]] = asyncio.Queue()
    malformed: list[ProtocolError] = []
    """Status packets that did not decode: skipped, and named if no good one comes in time."""

    def on_numbers(packet: Packet) -> None:
        try:
            n = packet.decode()
        except ProtocolError as exc:
            malformed[:] = [exc]
            return
        if isinstance(n, UpdateNumbers):
            robot[0] = replace(robot[0], **numbers_fields(n))
        elif isinstance(n, Update):
            robot[0] = replace(robot[0], **numbers_fields(n.numbers), **strings_fields(n))
        else:
            return
        queue.put_nowait({**status_object(robot[0]), **dock})

    def on_strings(packet: Packet) -> None:
        try:
            s = packet.decode()
        except ProtocolError:
            return
        if isinstance(s, UpdateStrings):
            robot[0] = replace(robot[0], **strings_fields(s))

    if client.supports("updateNumbers"):
        if client.supports("updateStrings"):
            client.request("updateStrings", -1, on_strings)
        client.request("updateNumbers", args.interval, on_numbers)
    elif client.supports("update"):
        client.request("update", args.interval, on_numbers)
    else:
        raise no_status(client)
    shown = 0
    # A status must come within the interval plus the timeout, or the link is dead.
    gap = args.interval / 1000.0 + args.timeout
    loop = asyncio.get_running_loop()
    quiet_after = max(1.0, 5 * args.interval / 1000.0)
    """Silence this long is worth a word on stderr before the timeout ends the stream."""
    last = loop.time()
    quiet = False
    printed: dict[str, Any] | None = None
    printed_at = 0.0
    while args.count <= 0 or shown < args.count:
        deadline = loop.time() + gap
        while queue.empty():
            if not quiet and loop.time() - last >= quiet_after:
                quiet = True
                quiet_for = quantity(loop.time() - last, "s", 1)
                say(_("no status for {time} — the server has gone quiet").format(time=quiet_for))
            if client.closed_error is not None:
                raise client.closed_error
            if loop.time() >= deadline:
                if malformed:
                    raise ProtocolFault(f"no usable status for {gap:g} s: {malformed[0]}")
                raise ClientTimeout(f"no status from the server for {gap:g} s")
            with contextlib.suppress(TimeoutError):
                async with asyncio.timeout(min(0.1, max(0.0, deadline - loop.time()))):
                    await queue.put(await queue.get())  # wait for one without taking it
        if quiet:
            quiet = False
            say(_("status resumed after {time}").format(time=quantity(loop.time() - last, "s", 1)))
        last = loop.time()
        current = queue.get_nowait()
        if current != printed or last - printed_at >= HEARTBEAT:  # a change, or the heartbeat is due
            show(current)
            printed, printed_at = current, last
            shown += 1
    return EXIT_OK

"""``rtmu call HOST[:PORT] NAME [ARG …]``: call any data the server lists, once or at an interval.

The console on the command line (:mod:`rtmu.client.console`): ``--list [FILTER]`` prints the
server's data list with its descriptions, argument and return descriptions, command group, flags
and whether a call changes something. A call sends the data once with ARGs typed as its argument
description says (``--type`` names the types where it says none RTMU can read) and prints each
reply packet as hex, as a best-effort field split, and as RTMU's own payload type where it has one;
``--every MS`` follows it instead (−1: only the server's broadcasts) until ``--seconds`` or Ctrl-C.
A data that changes something is sent only with ``--yes``, never followed, and ``ratioDrive`` never.

Exit codes (:mod:`rtmu.base.exit_codes`): 0 replied (a command without reply: the server took it);
2 usage — a data this user's list does not have, arguments that do not fit, a call that changes
something without ``--yes`` or one the console refuses (the reason is printed; nothing was sent);
3 connection (also when it ends while following); 5 silent — no reply within ``--timeout`` (no reply
at all while following), a reply
that stalled part way, or a command the server did not confirm taking.
"""

from __future__ import annotations

import argparse
import difflib
import re
import sys
import time
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_OK, EXIT_TIMEOUT, EXIT_USAGE, NETWORK
from ..base.i18n import _
from ..base.textsafe import visible
from ..client.console_layout import KINDS, ArgumentError, encode_arguments
from ..client.roles import Role
from ._common import add_connection_arguments, positive_float, print_json, run_with_client

if TYPE_CHECKING:
    from ..client.connection import AriaClient
    from ..client.console import ConsoleEntry, ConsoleReply

EXITS = NETWORK
FOLLOW_CHECK = 0.5
"""Seconds between looks at the connection while following a data."""


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "call",
        help=_("call any data the server lists (a console): once, or at an interval; --list shows them all"),
        description=_(
            "Send data NAME once with ARGs (typed as its argument description says, or as "
            "--type names) and print each reply as hex, fields and RTMU's own type where it has one. "
            "--every MS follows it (-1: broadcasts only). A data that changes something needs --yes (without "
            "it this command is an observer: it cannot send a motion request); ratioDrive is never "
            "sent. A data "
            "this user's list does not have, arguments that do not fit, a call that needs --yes, or "
            "one the "
            "console refuses are usage errors (nothing is sent); no reply within --timeout (none at "
            "all while "
            "following), a reply that stalls, or a command the server does not confirm taking is a timeout."
        ),
    )
    _positionals_anywhere(p)
    add_connection_arguments(p)
    p.add_argument("name", metavar="NAME", nargs="?", help=_("the data's name, as --list prints it"))
    p.add_argument("arguments", metavar="ARG", nargs="*", help=_("its arguments, in order"))
    p.add_argument(
        "--type",
        dest="types",
        action="append",
        metavar="TYPE[,TYPE…]",
        help=f"the type of each ARG, in order ({', '.join(KINDS)}); repeat or separate with commas",
    )
    p.add_argument(
        "--every",
        type=int,
        metavar="MS",
        help=_("follow the data: a reply every MS ms (-1: broadcasts only)"),
    )
    p.add_argument(
        "--seconds", type=positive_float, metavar="S", help=_("with --every: stop after S seconds")
    )
    p.add_argument(
        "--json", action="store_true", help=_("one JSON object per reply (or one array for --list)")
    )
    p.add_argument("--yes", action="store_true", help=_("confirm a call that changes something on the robot"))
    p.add_argument(
        "--list",
        dest="list_filter",
        nargs="?",
        const="",
        metavar="FILTER",
        help=_("list the server's data (those whose name, description or group contains FILTER)"),
    )
    p.set_defaults(handler=handle)


def _positionals_anywhere(parser: argparse.ArgumentParser) -> None:
    """NAME and ARGs may come after options (``HOST --user U NAME 5``), as in every other subcommand.

    argparse fills an optional NAME and ARG list with nothing at the first run of positionals (HOST
    alone) and then calls the later words unrecognised; they are taken back here, in order, before the
    connection arguments' own check refuses what is left (options it does not know).
    """
    parse_known = parser.parse_known_args

    def parse_known_args(args: Any = None, namespace: Any = None) -> tuple[argparse.Namespace, list[str]]:
        namespace, extras = parse_known(args, namespace)
        words: list[str] = []
        rest: list[str] = []
        for arg in extras:
            (words if not arg.startswith("-") or _NUMBER.fullmatch(arg) else rest).append(arg)
        if words and getattr(namespace, "name", None) is None:
            namespace.name = words.pop(0)
        if words:
            namespace.arguments = [*(getattr(namespace, "arguments", None) or []), *words]
        return namespace, rest

    parser.parse_known_args = parse_known_args  # type: ignore[method-assign,assignment]


_NUMBER = re.compile(r"-\d+(\.\d*)?|-\.\d+")
"""A negative number is an ARG, not an option."""


def usage(message: str) -> int:
    print(_("rtmu call: {visible}").format(visible=visible(message)), file=sys.stderr)
    return EXIT_USAGE


def handle(args: argparse.Namespace) -> int:
    from ..client.console import call, console_entries, entry_of
    from ..client.console_text import SILENT_OUTCOMES

    listing = args.list_filter is not None
    if not listing and not args.name:
        return usage("give NAME (the data to call) or --list")
    if listing and (args.name or args.arguments):
        return usage("--list takes a FILTER, not NAME or ARGs")
    if args.every is not None and (args.every < -1 or args.every == 0):
        return usage("--every wants a period in ms (1 or more), or -1 for broadcasts only")
    if args.seconds is not None and args.every is None:
        return usage("--seconds goes with --every")
    types = [t.strip() for group in args.types or () for t in group.split(",") if t.strip()] or None

    async def body(client: AriaClient) -> int:
        if listing:
            return print_list(console_entries(client.datalist, args.list_filter), args.json)
        data = client.datalist.entry(args.name)
        if data is None:
            return not_listed(args.name, [e.name for e in client.datalist])
        entry = entry_of(data)
        try:
            payload = encode_arguments(entry.arguments, list(args.arguments), types)
        except ArgumentError as exc:
            return usage(f"{entry.name}: {exc}")
        if args.every is not None:
            return await follow(client, entry, payload, args)
        reply = await call(client, entry, payload, confirmed=args.yes, timeout=args.timeout)
        show(reply, entry, args.json, args.timeout)
        return EXIT_TIMEOUT if reply.outcome in SILENT_OUTCOMES else EXIT_OK

    # Only a confirmed call (--yes) may be one that changes motion; without it this client cannot send one.
    role = Role.OPERATOR if getattr(args, "yes", False) else Role.OBSERVER
    return run_with_client("call", args, body, role=role)


async def follow(client: AriaClient, entry: ConsoleEntry, payload: bytes, args: argparse.Namespace) -> int:
    from ..client.console import Subscription

    subscription = Subscription(client, entry, args.every, payload).start()  # ConsoleRefusal: exit 2
    deadline = None if args.seconds is None else time.monotonic() + args.seconds
    replies = 0
    try:
        while deadline is None or time.monotonic() < deadline:
            left = FOLLOW_CHECK if deadline is None else max(0.0, deadline - time.monotonic())
            wait = min(FOLLOW_CHECK, left)  # and look at the connection between waits
            reply = await subscription.next(wait)
            if reply is None:
                if not client.connected:
                    break
                continue
            replies += 1
            show(reply, entry, args.json, args.timeout)
    finally:
        subscription.stop()
    if client.closed_error is not None:  # the connection ended while following: exit 3, with why
        raise client.closed_error
    if not replies:
        print(
            _("rtmu call: {visible}: no reply while following it").format(visible=visible(entry.name)),
            file=sys.stderr,
        )
    return EXIT_OK if replies else EXIT_TIMEOUT


def not_listed(name: str, names: list[str]) -> int:
    near = difflib.get_close_matches(name, names, n=5)
    hint = f" (did you mean {', '.join(near)}?)" if near else ""
    return usage(
        f"no data {name!r} in this server's list for this user{hint}; rtmu call HOST --list shows them"
    )


def print_list(entries: list[ConsoleEntry], as_json: bool) -> int:
    from ..client.console_text import entry_lines

    if as_json:
        print_json([e.to_json() for e in entries])
        return EXIT_OK
    for e in entries:
        for line in entry_lines(e):
            print(line)
    print(_("{len} data").format(len=len(entries)), flush=True)
    return EXIT_OK


def show(reply: ConsoleReply, entry: ConsoleEntry, as_json: bool, timeout: float) -> None:
    from ..client.console_text import SILENT_OUTCOMES, outcome_line, packet_lines

    if as_json:
        print_json(reply.to_json())
        return
    stream = sys.stderr if reply.outcome in SILENT_OUTCOMES else sys.stdout
    print(outcome_line(reply, timeout), file=stream)
    for line in packet_lines(reply):
        print(line)
    sys.stdout.flush()

"""``rtmu say HOST[:PORT] TEXT``: have the robot speak a text (``say``, LD robots)."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_OK, EXIT_USAGE
from ..base.i18n import _
from ..client.roles import Role
from ._common import add_connection_arguments, run_with_client

if TYPE_CHECKING:
    from ..client.connection import AriaClient

MAX_TEXT = 1000
"""Characters; a longer text is refused before connecting."""


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "say",
        help=_("have the robot speak a text (LD robots)"),
        description=_("Send say TEXT (the robot's text-to-speech); exit 4 if the server cannot speak."),
    )
    add_connection_arguments(p)
    p.add_argument("text", metavar="TEXT", help=_("what to say (latin-1, at most 1000 characters)"))
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..client import ld_data

    text = args.text.strip()
    if not text or len(text) > MAX_TEXT:
        print(
            _("rtmu say: give a text of 1…{MAX_TEXT} characters").format(MAX_TEXT=MAX_TEXT), file=sys.stderr
        )
        return EXIT_USAGE
    try:
        text.encode("latin-1")
    except UnicodeEncodeError:
        print(
            _("rtmu say: the text has characters ARIA strings cannot carry (latin-1 only)"), file=sys.stderr
        )
        return EXIT_USAGE

    async def body(client: AriaClient) -> int:
        ld_data.say(client, text)
        return EXIT_OK

    return run_with_client("say", args, body, role=Role.OBSERVER)

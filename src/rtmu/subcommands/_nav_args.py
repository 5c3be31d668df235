"""The parser's half of ``rtmu goto / home / dock / localize``: their exit codes and shared options.

Loaded with a command's parser (``rtmu goto --help`` too); :mod:`._navigate`, which follows the robot
(and loads the protocol's navigation values for it), is imported when a command runs.
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from ..base.exit_codes import EXIT_CANCELLED, EXIT_LOST, EXIT_REFUSED, NETWORK
from ..base.i18n import Said, _
from ..client.errors import NotSupported
from ._common import positive_float

if TYPE_CHECKING:
    from ..client.connection import AriaClient

EXIT_NAV_FAILED = EXIT_REFUSED
"""The server could not get there (``Failed to get to …``, ``Failed to plan to …``, ``Failed dock``)."""
EXIT_NAV_CANCELLED = EXIT_CANCELLED
"""It stopped before arriving: someone pressed STOP, drove, or sent the robot elsewhere."""
EXIT_NAV_LOST = EXIT_LOST
"""The robot is lost: navigation failed for that, or ``rtmu localize`` ended lost. Localize it first."""
NAVIGATION_EXITS = (*NETWORK, EXIT_REFUSED, EXIT_CANCELLED, EXIT_LOST)

DEFAULT_LIMIT = 600.0


def add_wait_arguments(parser: argparse.ArgumentParser, *, localizing: bool = False) -> None:
    """``--limit``, ``--no-wait``, ``--json``: how long to follow the server's words, how to print them."""
    if localizing:
        limit = _("give up waiting for the server's answer after S seconds, exit 5 (default {limit})")
        no_wait = _("send localizeToPose and exit 0 without waiting for the server to confirm it")
        lines = _(
            'one object per line: {"localization": "initializing"} while it '
            'localizes, then {"outcome": "localized" | "lost" | "timeout", "score"}; --no-wait: {"sent"}'
        )
    else:
        limit = _("give up after S seconds: stop the robot, exit 5 (default {limit})")
        no_wait = _("send the command and exit 0; the robot drives on by itself")
        lines = _(
            'one object per line: {"status", "phase"} as the server reports, '
            '{"remaining_mm"} every metre or so, and a last '
            '{"outcome", "text", "reason", "x", "y", "th"} '
            '(also after Ctrl-C: outcome "interrupted", with "signal"); --no-wait: {"sent"}'
        )
    limit = limit.format(limit=f"{DEFAULT_LIMIT:g}")
    parser.add_argument("--limit", type=positive_float, default=DEFAULT_LIMIT, metavar="S", help=limit)
    parser.add_argument("--no-wait", action="store_true", help=no_wait)
    parser.add_argument("--json", action="store_true", help=lines)


def require(client: AriaClient, name: str, sentence: str) -> None:
    """NotSupported (exit 4) with plain words when the server does not list ``name``: ``sentence``, a
    marked template (``N_("this server does not drive home (it does not offer {name})")``)."""
    if not client.supports(name):
        raise NotSupported(name, Said(sentence, name=name))

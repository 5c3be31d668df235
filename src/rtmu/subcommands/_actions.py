"""What ``rtmu files`` and ``rtmu scan`` share: an action word after ``HOST[:PORT]``, options on either side.

``rtmu files HOST ls --timeout 3`` and ``rtmu files HOST --timeout 3 ls`` both work: the connection options
are also accepted after the action (argparse would otherwise stop at it). A progress line goes to stderr
only on a terminal.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..base.i18n import _
from ..base.units import file_size, percent
from ._common import _RefusePassword, positive_float


def add_late_connection_options(parser: argparse.ArgumentParser) -> None:
    """The connection options again, for after the action word (unset unless given there)."""
    parser.allow_abbrev = False
    quiet = argparse.SUPPRESS
    parser.add_argument("--user", default=quiet, help=_("user name, if the server has a user file"))
    parser.add_argument("--password", nargs="?", action=_RefusePassword, help=quiet)
    parser.add_argument(
        "--password-file", type=Path, metavar="FILE", default=quiet, help=_("read the password from FILE")
    )
    parser.add_argument(
        "--password-stdin",
        action="store_true",
        default=quiet,
        help=_("read the password from the first line of standard input"),
    )
    parser.add_argument(
        "--protocol", metavar="STRING", default=quiet, help=_("protocol string to log in with")
    )
    parser.add_argument(
        "--timeout", type=positive_float, metavar="S", default=quiet, help=_("seconds to wait at each step")
    )
    parser.add_argument("--robot", metavar="NAME", default=quiet, help=_("a robot behind a central server"))


def action_parser(actions: Any, name: str, help_text: str, description: str) -> argparse.ArgumentParser:
    p: argparse.ArgumentParser = actions.add_parser(name, help=help_text, description=description)
    add_late_connection_options(p)
    p.add_argument("--json", action="store_true", help=_("one JSON object on stdout"))
    return p


def progress_printer(what: str) -> Callable[[int, int | None], None] | None:
    """A ``progress(done, total)`` redrawing one stderr line, at most 10 a second (None off a terminal)."""
    if not sys.stderr.isatty():
        return None
    last = [0.0]

    def show(done: int, total: int | None) -> None:
        now = time.monotonic()
        if now - last[0] < 0.1 and done != total:
            return
        last[0] = now
        part = (
            _("{percent} of {total}").format(percent=percent(100 * done / total), total=file_size(total))
            if total
            else file_size(done)
        )
        sys.stderr.write(f"\r{what}: {part}   ")
        sys.stderr.flush()

    return show


def end_progress(printer: object) -> None:
    if printer is not None:
        sys.stderr.write("\r\x1b[K")
        sys.stderr.flush()

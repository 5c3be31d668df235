"""``rtmu replay FILE.mcap [--conn N]``: the window, showing a recording (its first connection by default).

The file is read first, headless, so a file that is no replayable recording gets its
reason on stderr and exit 16 without a window (a missing file: exit 2). The window then
rebuilds every part of the state from the recorded bytes; nothing is ever sent to a robot.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ..base.exit_codes import EXIT_BAD_FILE, EXIT_NO_DISPLAY, EXIT_OK, EXIT_USAGE
from ..base.i18n import _
from ._common import fail
from ._options import number_in

EXITS = (EXIT_OK, EXIT_USAGE, EXIT_NO_DISPLAY, EXIT_BAD_FILE)


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "replay",
        help=_("open the window on a recording (play, pause, speed, timeline); nothing drives"),
        description=_(
            "Show a flight recording (rtmu record, or the window's own) in the operator window as "
            "it was live: map, robot, trail, sonar, camera, banners. Play, pause, x0.25-x8, scrub and step. "
            "Drive keys, the D-pad and STOP send nothing."
        ),
    )
    p.add_argument("file", type=Path, metavar="FILE.mcap", help=_("the recording"))
    p.add_argument(
        "--conn",
        type=number_in(1, 1_000_000, integer=True),
        default=1,
        metavar="N",
        help=_("which connection of the file, counted from 1 (default 1: the first)"),
    )
    p.add_argument("--fullscreen", action="store_true", help=_("start full screen (F11 toggles)"))
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..recorder.replay_file import ReplayFileError, load

    path: Path = args.file
    if not path.exists():
        return fail("replay", f"{path} does not exist", EXIT_USAGE)
    if not path.is_file():
        return fail("replay", f"{path} is not a file", EXIT_USAGE)
    try:
        recorded = load(path, args.conn)
    except ReplayFileError as exc:
        return fail("replay", str(exc), EXIT_BAD_FILE)
    for warning in recorded.warnings:
        fail("replay", f"warning: {warning}", 0)
    from ..ui import app as gui_app

    args.replay = path
    args.replay_conn = args.conn
    args.no_connect = True
    return gui_app.run_gui(args)

"""Where RTMU's own log lines go: developer notices stay off the operator's terminal.

The modules log what a developer wants to know (a handler that held the network loop for
12 ms, a recording's writer stopping); the operator already gets the part that matters as a
plain message or notice. So in normal use only errors (a bug: RTMU's own traceback) reach
stderr; ``RTMU_LOG=warning`` (or ``info``, ``debug``) shows more, and ``rtmu sim --verbose``
turns on the simulator's connection log.
"""

from __future__ import annotations

import logging
import os
import sys

ENV = "RTMU_LOG"
FORMAT = "rtmu: %(levelname)s %(name)s: %(message)s"


def configure(level: int | None = None) -> None:
    """Show ``rtmu`` log lines at ``level`` and above on stderr (default: ``$RTMU_LOG``, else errors).

    Called by the command line before any subcommand runs; calling again changes the level. Lines
    still propagate (a test's log capture sees them); only Python's last-resort printing of every
    warning is replaced.
    """
    named = os.environ.get(ENV, "").strip().upper()
    wanted = logging.getLevelNamesMapping().get(named) if level is None else level
    logger = logging.getLogger("rtmu")
    handler = next((h for h in logger.handlers if getattr(h, "rtmu_stderr", False)), None)
    if handler is None:
        handler = logging.StreamHandler(sys.stderr)
        handler.rtmu_stderr = True  # type: ignore[attr-defined]
        handler.setFormatter(logging.Formatter(FORMAT))
        logger.addHandler(handler)
    handler.setLevel(logging.ERROR if wanted is None else wanted)
    if wanted is not None and wanted < logging.WARNING:
        logger.setLevel(wanted)

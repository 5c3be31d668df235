"""The guard's scanning rule: while the robot scans for a map, only the operator's own hands move it.

A scan (ARIA's ``ArServerHandlerMapping``) logs what the laser sees along the path the operator
drives; ARIA refuses nothing while it runs, so RTMU does: a goal, a jog, a patrol or a server command
that may drive would add a path the operator did not choose to the log. Held drives (the keys, the
D-pad, a gamepad) are not intents and go on as usual, and STOP is never an intent that moves: it
always goes out (:meth:`~rtmu.control.controller.Controller.ask` handles it before any rule).
"""

from __future__ import annotations

from ..values.commission import ScanState
from ..values.intents import Intent
from . import intent_rules


def scan_refusal(intent: Intent, scan: ScanState) -> str | None:
    """Why ``intent`` is refused while ``scan`` runs (None: it may go)."""
    if not scan.scanning or not intent_rules.moves(intent):  # a console call of a motion request too
        return None
    return (
        f"{intent.label}: not while scanning for a map ({scan.file_name or scan.name}) — "
        "drive by hand, or stop the scan first"
    )

"""The guard's rules that depend on what an intent carries, not only on its type.

:meth:`rtmu.control.controller.Controller.ask` applies the rules every intent shares (replay, the
server's offer, a held drive ends before motion); these are the ones a value decides:

* a console call (:class:`~rtmu.values.intents.ConsoleCall`) of a motion request moves the robot
  whatever the class says — it ends a held drive first, as every moving intent does — and is refused
  until the operator confirms it; ``ratioDrive`` is never the console's (held motion comes only from a
  held drive); a motion request is never followed at an interval;
* a fix that changes how the robot protects itself or acts on a robot whose layouts are not public
  (:data:`~rtmu.values.intents.FIXES_NEEDING_YES`) is refused without the operator's yes.

The network side checks again (``client.console`` refuses any unconfirmed change, ``client.why_fix``
asks before a fix that needs a yes): the window's word is never the only guard.
"""

from __future__ import annotations

from ..base.i18n import N_
from ..client.console_effect import HELD_MOTION, moves_robot
from ..values.intents import FIXES_NEEDING_YES, ApplyFix, ConsoleCall, ConsoleFollow, Intent

FIX_WORDS = {
    "safe_drive_off": N_("switching safe drive off lets the robot drive into things"),
    "acknowledge_faults": N_("acknowledging the robot's faults may let it move on"),
    "enable_motors": N_("enabling the motors powers the robot's wheels"),
}
"""Why a fix asks first (English; marked, translated where the confirmation shows it)."""


def moves(intent: Intent) -> bool:
    """The intent starts, changes or ends the robot's motion (its class says so, or the data it names)."""
    if isinstance(intent, ConsoleCall):
        return moves_robot(intent.name)
    return intent.moves


def refusal(intent: Intent) -> str | None:
    """Why the guard refuses ``intent`` as it stands (None: these rules let it through)."""
    if isinstance(intent, ConsoleCall | ConsoleFollow) and intent.name in HELD_MOTION:
        return (
            f"{intent.name} is never sent from the console: held motion comes only from a held drive "
            "(the keys, the D-pad, the gamepad's dead-man)"
        )
    if isinstance(intent, ConsoleFollow) and intent.on and moves_robot(intent.name):
        return f"{intent.name} moves the robot: it is never followed at an interval (call it once)"
    if isinstance(intent, ConsoleCall) and moves_robot(intent.name) and not intent.confirmed:
        return f"{intent.name} changes how the robot moves: not sent without the operator's confirmation"
    if isinstance(intent, ApplyFix) and intent.key in FIXES_NEEDING_YES and not intent.confirmed:
        words = FIX_WORDS.get(intent.key, intent.key)
        return f"not sent without the operator's confirmation ({words})"
    return None

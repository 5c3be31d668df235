"""Does calling a data change something? Judged from its name, description and flags — biased to yes.

A console can call any of the hundreds of data an LD robot lists, most of which RTMU knows nothing
about. Only a plain read may run without the operator's confirmation, so :func:`classify` calls a
data a read only when nothing in its name or description suggests an effect: a verb such as
set / delete / enable / acknowledge / reset / stop anywhere in the name, a motion or mission verb
(go, move, drive, dock, patrol, say …) that the name does not turn into a noun (``dockInfo`` is a
read), a description that opens with such a verb ("Sends the robot to its dock"), or a data that
returns nothing (ARIA's commands) all mean "changes something"; a motion request
(:func:`moves_robot`) always does, whatever its words. Each answer carries the words that decided
it, so the operator can see why a confirmation is asked.

``ratioDrive`` is never the console's: held motion happens only while the operator holds a key,
through the drive lease (:data:`HELD_MOTION`). Every request of the one motion list
(:data:`rtmu.protocol.motion.MOTION_REQUESTS`) changes something whatever its description says: a
server that describes ``tourGoalsInList`` as a list of names does not make it a read.
"""

from __future__ import annotations

import re
from enum import Enum

from ..protocol.datalist import DataEntry
from ..protocol.motion import is_motion


class Effect(Enum):
    READ = "read"
    CHANGES = "changes something"


HELD_MOTION = frozenset({"ratioDrive"})
"""Data RTMU sends only from a held drive (its lease and guardian): the console refuses them."""


def moves_robot(name: str) -> bool:
    """Calling ``name`` starts, changes or ends the robot's motion (the one list an observer may never
    send, :data:`rtmu.protocol.motion.MOTION_REQUESTS`): always a change, confirmed in the window."""
    return is_motion(name)


STRONG = frozenset(
    {
        "set", "put", "delete", "del", "remove", "erase", "enable", "disable", "acknowledge", "ack",
        "reset", "clear", "cancel", "abort", "start", "stop", "add", "create", "make", "new", "rename",
        "save", "load", "restart", "shutdown", "reboot", "lock", "unlock", "write", "upload", "apply",
        "trigger", "execute", "kill", "override", "force", "change", "modify", "edit", "assign",
        "install", "calibrate", "click", "clicked", "simulator", "format", "estop", "on", "off", "end",
        "begin", "finish", "process", "reload", "push", "command", "throw", "allocate", "unallocate",
    }
)  # fmt: skip
"""Words that mean an effect wherever they stand in a name (``getAndResetCounters`` resets)."""
WEAK = frozenset(
    {
        "go", "goto", "move", "drive", "dock", "undock", "wander", "turn", "patrol", "say", "speak",
        "play", "pause", "resume", "home", "tour", "localize", "jog", "teleop", "switch", "run",
        "mark", "send", "pick", "drop", "queue", "beep", "stay", "extend", "fail",
    }
)  # fmt: skip
"""Motion and mission verbs that are also nouns: an effect unless the name reads them
(``getSafeDrive``) or ends in a reading noun (``dockInfo``)."""
READ_FIRST = frozenset({"get", "list", "query", "is", "has", "describe", "find", "show", "read", "fetch"})
READ_LAST = frozenset(
    {
        "info", "list", "status", "state", "current", "cumulative", "count", "name", "names", "id", "size",
        "progress", "done", "resumable", "points", "lines", "path", "paths", "data", "shape", "sector",
        "tree", "grid", "area", "trace", "stencils", "video", "picture", "image",
    }
)  # fmt: skip
BROADCAST_LAST = frozenset({"updated", "changed", "update"})
"""``mapUpdated``, ``dockInfoChanged``, ``faultsUpdate``: the server's news, read by subscribing."""
STATUS_AFTER_UPDATE = frozenset({"numbers", "strings"})
"""``update``, ``updateNumbers``, ``updateStrings`` are ARIA's status reads; ``updateConfigValues`` writes."""
_WORDS = re.compile(r"[A-Z]+(?=[A-Z][a-z])|[A-Z]?[a-z]+|[A-Z]+|\d+")
_DESCRIPTION_VERB = re.compile(
    r"\s*(?:sets?|changes?|deletes?|removes?|enables?|disables?|acknowledges?|clears?|resets?|starts?|"
    r"stops?|drives?|moves?|turns?|docks?|undocks?|patrols?|speaks?|says?|plays?|saves?|loads?|"
    r"creates?|adds?|renames?|restarts?|reboots?|shuts?|executes?|runs?|tells?|puts?|makes?|"
    r"cancels?|pauses?|resumes?|switch(?:es)?|locks?|unlocks?|forces?|triggers?|writes?|uploads?|"
    r"applies|apply|answers?|sends? the robot|takes? the robot|commands?)\b",
    re.IGNORECASE,
)


def name_words(name: str) -> list[str]:
    """``safetyStatusEStop`` → ``['safety', 'status', 'estop']`` (an "E" before "Stop" is e-stop)."""
    words = [w.lower() for w in _WORDS.findall(name)]
    joined: list[str] = []
    for w in words:
        if w == "stop" and joined and joined[-1] == "e":
            joined[-1] = "estop"
        else:
            joined.append(w)
    return joined


def classify(entry: DataEntry) -> tuple[Effect, str]:
    """:class:`Effect` of calling ``entry``, and the words that decided it."""
    words = name_words(entry.name)
    if entry.name in HELD_MOTION:
        return Effect.CHANGES, "it drives the robot while held (RTMU sends it only from a held drive)"
    if moves_robot(entry.name):  # whatever its words say (``tourGoalsInList`` ends in a reading noun)
        return Effect.CHANGES, "it starts, changes or ends the robot's motion"
    strong = next((w for w in words if w in STRONG and not (w == "estop" and _reads(words))), None)
    if strong is not None:
        return Effect.CHANGES, f"its name says {strong!r}"
    if words and words[0] == "update" and len(words) > 1 and words[1] not in STATUS_AFTER_UPDATE:
        return Effect.CHANGES, "its name says 'update'"
    verb = _DESCRIPTION_VERB.match(entry.description[:200])
    if verb is not None:
        return Effect.CHANGES, f"its description says {' '.join(verb.group().split())!r}"
    if words and words[0] in READ_FIRST:
        return Effect.READ, f"its name says {words[0]!r}"
    if words and words[-1] in BROADCAST_LAST:
        return Effect.READ, "the server's news of a change (a broadcast)"
    weak = None if any(w in READ_FIRST for w in words) else next((w for w in words if w in WEAK), None)
    if weak is not None and words[-1] not in READ_LAST:
        return Effect.CHANGES, f"its name says {weak!r}"
    if "RETURN_NONE" in entry.flag_set:
        return Effect.CHANGES, "it is a command: it returns nothing"
    if weak is not None:
        return Effect.READ, f"its name ends in {words[-1]!r}"
    return Effect.READ, "nothing in its name or description says it changes something"


def _reads(words: list[str]) -> bool:
    """An e-stop word in a name that reads it (``safetyStatusEStop``, ``getEStopState``) is a read."""
    return words[0] in READ_FIRST or words[-1] in READ_LAST or "status" in words or "count" in words

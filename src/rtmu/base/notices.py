"""Messages for the operator, typed by what they are about.

A notice carries its :class:`Kind` from where it is raised, so the window routes
it by kind (the link banner, the speed banner, the camera page …) and never by
the words in its text: a server popup that mentions the camera is still a popup.
GTK-free and thread-free; the runner posts notices to the UI thread.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum


class Level(Enum):
    INFO = "info"
    WARNING = "warning"
    ERROR = "error"


class Kind(Enum):
    """What a notice is about; each kind has one place in the window."""

    CONNECTION = "connection"
    """Connected, reconnecting, a failed attempt: the link banner shows these from the model."""
    LINK = "link"
    """The link's health: stopped for a stale link, reconnected."""
    SAFETY = "safety"
    """Motion stopped by a safety rule (a lapsed lease, the guardian)."""
    SPEED = "speed"
    """The speed step changed."""
    SPEED_LIMIT = "speed-limit"
    """The speed step is already at its minimum or maximum."""
    CAMERA = "camera"
    """A picture request and its failure."""
    MAP = "map"
    COMMAND = "command"
    """A command's result, or why it could not run."""
    SERVER = "server"
    """Text the server raised for the operator (popups, messages): shown as it is, never routed by it."""
    NAVIGATION = "navigation"
    RECORDING = "recording"
    """The flight recorder: it stopped (full disk, size limit) or could not start."""
    GENERAL = "general"


@dataclass(frozen=True, slots=True)
class Notice:
    kind: Kind
    level: Level
    text: str
    stop: bool = False
    """It explains a stop of the robot (the link, a lapse, lost focus, the guardian): the window also
    writes it, once, on stderr — the operator's terminal and a site's log keep every stop's words."""

    @classmethod
    def info(cls, kind: Kind, text: str) -> Notice:
        return cls(kind, Level.INFO, text)

    @classmethod
    def warning(cls, kind: Kind, text: str) -> Notice:
        return cls(kind, Level.WARNING, text)

    @classmethod
    def error(cls, kind: Kind, text: str) -> Notice:
        return cls(kind, Level.ERROR, text)

    @classmethod
    def stopped(cls, kind: Kind, text: str, level: Level = Level.WARNING) -> Notice:
        """A notice that explains why the robot was just stopped (``stop``)."""
        return cls(kind, level, text, stop=True)

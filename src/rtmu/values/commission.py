"""What a robot's commissioning shows the operator: the scan running on it, and files on their way.

Frozen values the network side publishes (``ScanChanged``, ``TransfersChanged`` in
:mod:`rtmu.values.state`) and the window shows: the scanning banner and the controller's guard read
:class:`ScanState`, the file page's progress bars read :class:`TransfersState`. GTK-free, thread-free.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum


@dataclass(frozen=True, slots=True)
class ScanState:
    """A scan for a map on the robot (ARIA's ``ArServerHandlerMapping``), as the robot last said."""

    offered: bool = False
    """The robot can scan (it lists ``mappingStart`` and ``mappingEnd``)."""
    name: str = ""
    """The running scan's name as the robot reports it; "" while none runs."""
    file_name: str = ""
    """The ``.2d`` file it is written to (checked: one plain name)."""
    since: float | None = None
    """When this session saw it start (the session's clock); None for a scan already running at login."""
    last_file: str = ""
    """The file of the scan that ended last while connected: what "Download the scan" fetches."""

    @property
    def scanning(self) -> bool:
        return bool(self.name)


class Direction(StrEnum):
    DOWNLOAD = "download"
    UPLOAD = "upload"


@dataclass(frozen=True, slots=True)
class Transfer:
    """One file on its way between the robot and this computer."""

    direction: Direction
    remote: str
    local: str
    done: int = 0
    """Bytes so far."""
    total: int | None = None
    """Bytes in all, when known (a download's listed size, an upload's file size)."""

    @property
    def fraction(self) -> float | None:
        if not self.total:
            return None
        return min(1.0, self.done / self.total)


@dataclass(frozen=True, slots=True)
class TransfersState:
    """The transfers under way on this connection (a finished one leaves; its asker has the answer)."""

    active: tuple[Transfer, ...] = ()

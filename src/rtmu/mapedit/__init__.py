"""Map editing below the window: a draft of edits to a map's objects, with undo, redo and rebase.

GTK-free and network-free (the values layer): the window and ``rtmu mapedit`` both build on
:class:`~rtmu.mapedit.draft.MapDraft`; ``rtmu.client.map_changes`` sends what it asks for. ``MapObject``
(a map's goal, dock, line or area) is named here too, so the window edits objects without reading maps.
"""

from ..mapfile import MapObject
from .draft import (
    Conflict,
    DraftError,
    Edit,
    MapDraft,
    ObjectChanges,
    Underneath,
    describe,
    object_key,
)

__all__ = [
    "Conflict",
    "DraftError",
    "Edit",
    "MapDraft",
    "MapObject",
    "ObjectChanges",
    "Underneath",
    "describe",
    "object_key",
]

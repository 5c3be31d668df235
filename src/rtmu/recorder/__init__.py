"""The flight recorder: every robot session written to one MCAP file (issue 12).

``recorder`` (one robot session: files per connection target, the hooks) →
``recording`` (one file and its writer thread, bounded queue) → ``mcapfile``
(foxglove-sdk's writer, channels) over ``sink`` (byte count, write errors);
``tee`` the link that copies the raw bytes, ``convert`` values → Foxglove messages,
``intents`` the operator's calls, ``files`` names, place and age, ``topics`` the
channel names. The raw channel's layout is :mod:`rtmu.capture.recorded`.

The package imports its modules when first asked for one of the names below (or by module), so
``from rtmu.recorder import topics`` and ``rtmu bridge --help`` do not load foxglove-sdk.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .recorder import Recorder, RecorderConfig
    from .recording import Limits, Recording

_HOMES = {
    "Recorder": "recorder",
    "RecorderConfig": "recorder",
    "Limits": "recording",
    "Recording": "recording",
}


def __getattr__(name: str) -> Any:
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{home}"), name)


__all__ = ["Limits", "Recorder", "RecorderConfig", "Recording"]

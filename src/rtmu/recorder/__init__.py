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

from typing import TYPE_CHECKING

from ..protocol import lazy

if TYPE_CHECKING:
    from .recorder import Recorder, RecorderConfig
    from .recording import Limits, Recording

__getattr__ = lazy.exports(
    __name__,
    {"Recorder": "recorder", "RecorderConfig": "recorder", "Limits": "recording", "Recording": "recording"},
)

__all__ = ["Limits", "Recorder", "RecorderConfig", "Recording"]

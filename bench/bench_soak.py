"""Short drive soaks for ``./rtmu-dev bench``: the client core, then the real window under Xvfb.

The hour-long ones are ``python -m bench.soak --seconds 3600 [--window]``. ``RTMU_SOAK_SECONDS``
sets each one's length here (default 90 s, so the whole bench run stays a few minutes).
"""

from __future__ import annotations

import os

from bench.common import Result
from bench.soak import results, soak
from bench.soak_window import soak_window

DEFAULT_SECONDS = 90.0


def run() -> list[Result]:
    seconds = float(os.environ.get("RTMU_SOAK_SECONDS", DEFAULT_SECONDS))
    return results(soak(seconds)) + results(soak_window(seconds), "soak.window")

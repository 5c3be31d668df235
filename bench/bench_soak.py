"""A short drive soak for ``./rtmu-dev bench``; the hour-long one is ``python -m bench.soak``.

``RTMU_SOAK_SECONDS`` sets the length (default 120 s, so the whole bench run stays a few minutes).
"""

from __future__ import annotations

import os

from bench.common import Result
from bench.soak import results, soak

DEFAULT_SECONDS = 120.0


def run() -> list[Result]:
    seconds = float(os.environ.get("RTMU_SOAK_SECONDS", DEFAULT_SECONDS))
    return results(soak(seconds))

"""How much longer than on a quiet desk a test waits, before it fails, for what it means.

CI's machine is shared and often busy (the suite itself runs on several workers of two cores), so
every bound a test waits under is multiplied by ``PATIENCE``: 3 on CI, 1 here, so that a developer
still sees a slow step. A bound is only how long a test waits before it fails: a passing wait
returns as soon as the thing happens, so a larger bound slows only failures.
"""

from __future__ import annotations

import os

_ON_CI = os.environ.get("CI", "").lower() in ("true", "1")
PATIENCE = float(os.environ.get("RTMU_TEST_PATIENCE") or (3.0 if _ON_CI else 1.0))


def cli_timeout(seconds: float) -> str:
    """A CLI's ``--timeout`` argument given as a generous bound (not a timeout the test waits for),
    with the suite's patience: a reply the busy machine sends late is still a reply."""
    return f"{seconds * PATIENCE:g}"

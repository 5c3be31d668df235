"""Where the suite's real ARIA material lives: ``tests/data`` of this repository, nothing beside it.

``captures/`` holds sessions recorded from ARIA 2.9.1's own programs and ``aria-maps/`` ARIA's example
maps (GPL-2, test data only: see each folder's README). Tests and benchmarks name these paths from
here, so a clone runs with nothing beside it (``tests/test_self_contained.py``).
"""

from __future__ import annotations

from pathlib import Path

TEST_DATA = Path(__file__).resolve().parent / "data"
CAPTURES = TEST_DATA / "captures"
ARIA_MAPS = TEST_DATA / "aria-maps"

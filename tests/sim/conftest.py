"""Fixtures for simulator tests: a manual-clock server on a free port, and the project's maps."""

from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
ARENA = REPO / "data" / "maps" / "arena.map"


@pytest.fixture
def arena_map() -> Path:
    if not ARENA.exists():
        pytest.skip("data/maps/arena.map is not built yet")
    return ARENA

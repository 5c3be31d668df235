"""Fixtures for simulator tests: the project's committed arena map."""

from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
ARENA = REPO / "data" / "maps" / "arena.map"


@pytest.fixture
def arena_map() -> Path:
    """``data/maps/arena.map`` is committed: its absence is a broken checkout, not a reason to skip."""
    if not ARENA.is_file():
        pytest.fail(f"{ARENA} is missing: it is part of the repository (restore it with git)")
    return ARENA

"""Fixtures for simulator tests: the project's committed arena map."""

from __future__ import annotations

from pathlib import Path

import pytest

from rtmu.package_data import project_map

ARENA = project_map("arena.map")


@pytest.fixture
def arena_map() -> Path:
    """``rtmu/data/maps/arena.map`` is committed: its absence is a broken checkout, not a reason to skip."""
    if not ARENA.is_file():
        pytest.fail(f"{ARENA} is missing: it is part of the repository (restore it with git)")
    return ARENA


@pytest.fixture(scope="session")
def million_point_map(tmp_path_factory) -> Path:
    """A generated 1 M-point building map: its binary stream (8 MB) is larger than a client may queue."""
    from rtmu.mapfile import write_map
    from rtmu.sim.mapgen import generate_map

    path = tmp_path_factory.mktemp("maps") / "million.map"
    write_map(generate_map(1_000_000, 5_000, seed=3), path)
    return path

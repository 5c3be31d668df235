"""A clone needs nothing beside it: no test, benchmark or module reads the folder beside the checkout.

The captured ARIA sessions and ARIA's maps the suite reads are in ``tests/data`` (``testdata``). One
test reads the sources for paths out of the repository; the other copies the tracked files into an
empty folder — no ``shared/`` beside it — and runs there a representative part of the suite that uses
those captures and maps, with the copy's own ``src`` as the package.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

from checkout import ROOT, copy_tracked, tracked_files

OUTSIDE = re.compile(
    r"""\.\./shared\b|/work/shared\b|["']\.\.["']\s*/\s*["']shared["']|\bparent\s*/\s*["']shared["']"""
    r"""|/\s*["']shared["']\s*/"""
)
"""The sibling folder by path: the absolute one under ``/work``, ``..`` joined to it, a root's parent
joined to it, ``X / <it> / …`` (the examples below are written in pieces: this file names no such folder)."""

SHARED_DATA_USERS = [
    "tests/test_maps_aria.py",
    "tests/test_ptz_captures.py",
    "tests/test_maps_project.py",
    "tests/sim/test_commands_capture.py",
    "tests/client/test_video_feed.py",
    "tests/protocol/test_datalist.py::test_the_captured_catalogue_of_a_real_server",
    "tests/test_golden_captures.py::test_the_captures_are_there",
    "tests/test_golden_captures.py::test_drive_capture_statuses_match_the_decoded_poses_file",
]
"""A cheap sample of the tests that read tests/data (captures, ARIA maps) and the package's own maps."""


def test_no_source_names_a_folder_outside_the_repository() -> None:
    this = Path(__file__).relative_to(ROOT).as_posix()
    offenders = []
    for name in tracked_files():
        if name == this or (not name.endswith((".py", ".sh", ".toml", ".cfg")) and name != "rtmu-dev"):
            continue
        for number, line in enumerate((ROOT / name).read_text(errors="replace").splitlines(), 1):
            if OUTSIDE.search(line):
                offenders.append(f"{name}:{number}: {line.strip()}")
    assert not offenders, "paths outside the repository:\n" + "\n".join(offenders)


def test_the_pattern_sees_each_way_of_naming_shared() -> None:
    for line in (
        'SHARED = Path(__file__).resolve().parents[1].parent / "' + 'shared"',
        'Path("/work/shared/aria-maps")',
        "see .." + "/shared/captures",
        'Path(__file__).parents[2] / ".." / "shared"',
        'REPO / "shared" / "captures"',
    ):
        assert OUTSIDE.search(line), line
    assert not OUTSIDE.search('server_key="shared"') and not OUTSIDE.search("map_downloads_shared")


def test_a_copy_with_nothing_beside_it_runs_the_tests_that_read_captures_and_maps(tmp_path: Path) -> None:
    clone = copy_tracked(tmp_path / "alone" / "rtmu")
    assert sorted(p.name for p in clone.parent.iterdir()) == ["rtmu"]  # no shared/ beside it
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTEST_", "RTMU_"))}
    env["PYTHONPATH"] = str(clone / "src")
    where = subprocess.run(
        [
            sys.executable,
            "-c",
            "import rtmu, rtmu.package_data as d; print(rtmu.__file__); print(d.MAPS_DIR)",
        ],
        cwd=clone,
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert where.returncode == 0, where.stderr
    assert all(Path(p).is_relative_to(clone) for p in where.stdout.split()), where.stdout
    run = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *SHARED_DATA_USERS],
        cwd=clone,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-2000:]
    assert re.search(r"\b\d+ passed\b", run.stdout) and "skipped" not in run.stdout, run.stdout[-2000:]

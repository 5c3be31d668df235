"""A GUI test run leaves nothing in the temporary directory but its screenshot folder."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_a_gui_run_leaves_only_its_screenshots_in_tmp(tmp_path: Path) -> None:
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    env = dict(os.environ, TMPDIR=str(tmp))
    for name in ("DISPLAY", "XDG_CONFIG_HOME", "RTMU_GUI_TMP", "RTMU_SCREENSHOTS"):
        env.pop(name, None)  # the inner run starts its own Xvfb and its own scratch root
    tests = [
        "tests/gui/test_views.py::test_wifi_not_published_is_greyed_with_a_reason",
        "tests/gui/test_views.py::test_without_a_map_the_stage_shows_a_grid_the_robot_as_a_circle_and_says_so",
    ]
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            f"--basetemp={tmp_path / 'base'}",
            *tests,
        ],
        cwd=REPO,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    left = sorted(p.name for p in tmp.iterdir())
    assert len(left) == 1 and left[0].startswith("rtmu-gui-screens-"), left
    shots = sorted(p.name for p in (tmp / left[0]).iterdir())
    assert shots and all(name.endswith(".png") for name in shots), shots

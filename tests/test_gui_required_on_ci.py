"""Without Xvfb or xdotool the GUI tests skip on a developer's machine but fail on CI (CI=true):
a green CI run must mean the window was tested."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
ONE_GUI_TEST = "tests/gui/test_frame_pixels.py::test_every_helper_starts_its_own_path"


def _run_without_xvfb(ci: str | None) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("CI", "DISPLAY")}
    env["PATH"] = str(Path(sys.executable).parent)  # the venv only: no Xvfb, no xdotool
    if ci is not None:
        env["CI"] = ci
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-rfs", "-p", "no:cacheprovider", ONE_GUI_TEST],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.mark.parametrize("ci", ["true", "1"])
def test_on_ci_missing_xvfb_fails_the_gui_tests(ci: str) -> None:
    result = _run_without_xvfb(ci)
    assert result.returncode == 1, result.stdout
    assert "CI=true but the GUI cannot be tested: Xvfb and xdotool are needed" in result.stdout
    assert " skipped" not in result.stdout.splitlines()[-1]


def test_locally_missing_xvfb_skips_with_the_reason() -> None:
    result = _run_without_xvfb(None)
    assert result.returncode == 0, result.stdout
    assert "skipped" in result.stdout.splitlines()[-1]
    assert "Xvfb and xdotool are needed for the GUI tests (apt-get install xvfb xdotool)" in result.stdout

"""A failing GUI test fails alone: it leaves no held key, window or process to the next test.

A pytest of its own runs ``tests/gui/isolation_probe.py``: its first test drives the robot from the
real window (a separate ``rtmu`` process against an ``rtmu sim`` process) and fails on purpose in the
middle, with no cleanup of its own; its second test must then pass on a clean display. Afterwards no
process of that run may be left: every one is found by an environment mark that all of them inherit
(the window's guardian too, even after it has been orphaned).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
import uuid
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
MARK = "RTMU_ISOLATION_RUN"

pytestmark = pytest.mark.gui


def _marked(value: str) -> list[str]:
    needle = f"\0{MARK}={value}\0".encode()
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            if needle in b"\0" + (entry / "environ").read_bytes() + b"\0":
                state = (entry / "stat").read_text().rsplit(")", 1)[1].split()[0]
                if state != "Z":
                    found.append(
                        (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
                    )
        except OSError:
            continue
    return found


def _probe(run: str, tmp_path: Path, select: str) -> str:
    env = dict(
        os.environ, RTMU_ISOLATION_PROBE="1", RTMU_ISOLATION_PIDS=str(tmp_path / "pids"), **{MARK: run}
    )
    env.pop("DISPLAY", None)  # the inner run starts its own Xvfb, as the suite does
    argv = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "tests/gui/isolation_probe.py"]
    result = subprocess.run(
        [*argv, "-k", select], cwd=REPO, env=env, capture_output=True, text=True, timeout=300
    )
    return result.stdout + result.stderr


def _nothing_left(run: str) -> None:
    deadline = time.monotonic() + 10
    while (left := _marked(run)) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not left, f"processes left behind by the run: {left}"


def test_a_gui_test_that_fails_while_driving_fails_alone(tmp_path: Path) -> None:
    run = uuid.uuid4().hex
    pids = tmp_path / "pids"
    out = _probe(run, tmp_path, "test_1 or test_2")
    counts = re.search(r"(\d+) failed, (\d+) passed", out)
    assert counts and counts.groups() == ("1", "1"), out
    assert "failing on purpose while Up is held" in out, out
    assert "test_1_fails_while_driving" in out and "FAILED" in out
    assert pids.read_text().split(), "the first test never reached its drive"
    _nothing_left(run)


def test_a_passing_gui_test_that_leaks_a_process_fails(tmp_path: Path) -> None:
    run = uuid.uuid4().hex
    out = _probe(run, tmp_path, "test_3")
    assert re.search(r"1 passed, 5 deselected, 1 error", out), out
    assert "left 0 app(s) open, windows on screen [] and 1 process(es) running" in out, out
    assert "time.sleep(120)" in out, out
    _nothing_left(run)


def test_a_passing_gui_test_that_leaves_a_window_on_screen_fails(tmp_path: Path) -> None:
    run = uuid.uuid4().hex
    out = _probe(run, tmp_path, "test_4")
    assert re.search(r"1 passed, 5 deselected, 1 error", out), out
    assert "windows on screen ['Left on screen']" in out, out
    _nothing_left(run)


def test_a_test_that_fails_with_a_popover_open_leaves_the_keyboard_to_the_next(tmp_path: Path) -> None:
    """A popover's X grab outlived its window: every later test's keys went to a dead surface."""
    run = uuid.uuid4().hex
    out = _probe(run, tmp_path, "test_5 or test_6")
    counts = re.search(r"(\d+) failed, (\d+) passed", out)
    assert counts and counts.groups() == ("1", "1"), out
    assert "failing on purpose with the menu open" in out, out
    _nothing_left(run)

"""Suite-wide settings (the ARIA captures and maps the tests read are in ``tests/data``: ``testdata``)."""

from __future__ import annotations

import atexit
import os
import shutil
import tempfile
from pathlib import Path

import pytest
from hypothesis import settings

from checkout import build_dists

# The window records every session (rtmu.recorder) under $XDG_DATA_HOME: never into the real home
# from a test, nor from the windows and subprocesses tests start (they inherit this environment).
os.environ["XDG_DATA_HOME"] = _DATA_HOME = tempfile.mkdtemp(prefix="rtmu-test-data-")
# Removed when the run ends (a GUI run must leave only its screenshots in /tmp: tests/gui/test_cleanup.py).
atexit.register(shutil.rmtree, _DATA_HOME, ignore_errors=True)

# Hypothesis's own "ci" profile (deterministic, no deadline) loads itself when CI is set. Locally we
# only drop the 200 ms deadline: other work shares these two cores, and speed is bench/'s business.
if "CI" not in os.environ:
    settings.register_profile("rtmu-local", deadline=None)
    settings.load_profile("rtmu-local")


@pytest.fixture(scope="session")
def built_dists(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """The sdist and wheel ``python -m build`` makes of this checkout, built once per run."""
    return build_dists(tmp_path_factory.mktemp("dists"))

"""Make something once a test run, even when the run is spread over pytest-xdist's workers.

Why: a session or module fixture is made once per worker process, so an expensive one (the dists'
build, a virtualenv with the wheel installed: tens of seconds of CPU each) was made once per worker.
The first worker that needs it makes it in the run's shared temp folder under a lock; the others wait
for the lock and take what it made. A failed attempt leaves no mark, so the next one tries again.
"""

from __future__ import annotations

import fcntl
import os
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest


def run_once(factory: pytest.TempPathFactory, name: str, make: Callable[[Path], list[Path]]) -> list[Path]:
    """``make(folder)``'s paths, made once a run in ``folder`` (the run's shared ``name`` folder)."""
    root = factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent  # the folder every worker's temp folder is in
    folder, done = root / name, root / f"{name}.done"
    with open(root / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not done.exists():
            shutil.rmtree(folder, ignore_errors=True)  # what a failed attempt left
            folder.mkdir()
            made = make(folder)
            done.write_text("".join(f"{p}\n" for p in made))
        return [Path(line) for line in done.read_text().splitlines()]

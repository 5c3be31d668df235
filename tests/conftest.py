"""Suite-wide settings (the ARIA captures and maps the tests read are in ``tests/data``: ``testdata``)."""

from __future__ import annotations

import atexit
import contextlib
import faulthandler
import functools
import importlib
import importlib.util
import os
import shutil
import sys
import tempfile
import time
from collections.abc import Iterator, Sequence
from pathlib import Path

import pytest
from hypothesis import settings

from checkout import build_dists
from run_once import run_once

# The window records every session (rtmu.recorder) under $XDG_DATA_HOME: never into the real home
# from a test, nor from the windows and subprocesses tests start (they inherit this environment).
os.environ["XDG_DATA_HOME"] = _DATA_HOME = tempfile.mkdtemp(prefix="rtmu-test-data-")
# Removed when the run ends (a GUI run must leave only its screenshots in /tmp: tests/gui/test_cleanup.py).
atexit.register(shutil.rmtree, _DATA_HOME, ignore_errors=True)
# The same for the user's cache (rtmu.base.dataclass_code keeps compiled dataclass methods there).
os.environ["XDG_CACHE_HOME"] = _CACHE_HOME = tempfile.mkdtemp(prefix="rtmu-test-cache-")
atexit.register(shutil.rmtree, _CACHE_HOME, ignore_errors=True)

# One folder for the GUI tests' screenshots, named once by the run that starts here: the workers of a
# parallel run (pytest-xdist) and the pytest runs a test starts inherit it, so a run's pictures are in one
# place and no worker removes a folder another still fills. Only the run that named it removes it (empty).
_NAMED_SCREENSHOTS = "RTMU_SCREENSHOTS" not in os.environ
os.environ.setdefault(
    "RTMU_SCREENSHOTS",
    str(Path(tempfile.gettempdir()) / f"rtmu-gui-screens-{time.strftime('%Y%m%d-%H%M%S')}"),
)

# The suite reads RTMU's English words (and GTK's): a fixed language, whatever the machine's, for this
# process and every window and subprocess it starts (tests of other languages choose theirs explicitly).
os.environ["LANGUAGE"] = "en"
os.environ["LC_ALL"] = "C.UTF-8"

# Hypothesis's own "ci" profile (deterministic, no deadline) loads itself when CI is set. Locally we
# only drop the 200 ms deadline: other work shares these two cores, and speed is bench/'s business.
if "CI" not in os.environ:
    settings.register_profile("rtmu-local", deadline=None)
    settings.load_profile("rtmu-local")


def _every_exit_code_is_one_its_help_lists() -> None:
    """Every subcommand a test runs in this process (``rtmu.cli.main``) ends with a code its ``--help``
    lists (its module's ``EXITS``, from the one table): the contract checked by every CLI test, not
    only by tests/test_exit_codes.py. Wrapped before any test module imports ``main``."""
    import rtmu.cli
    from rtmu.base import exit_codes

    run = rtmu.cli.main

    @functools.wraps(run)
    def main(argv: Sequence[str] | None = None) -> int:
        code = run(argv)
        name = next(iter(argv or ()), "")
        if name and not name.startswith(("-", "_")) and importlib.util.find_spec(f"rtmu.subcommands.{name}"):
            module = importlib.import_module(f"rtmu.subcommands.{name}")
            listed = getattr(module, "EXITS", exit_codes.NETWORK)
            assert code in listed, (
                f"rtmu {name} exited {code}, which its --help does not list: {sorted(listed)}"
            )
        return code

    rtmu.cli.main = main


_every_exit_code_is_one_its_help_lists()


HANG_EXIT_AFTER = 120.0
"""Seconds past pytest-timeout's own limit after which a test still running is taken as stuck where no
Python signal handler can run (inside a C call: an X or D-Bus round trip): every thread's traceback is
written and the run ends, so a hung call costs CI minutes and says where, not the whole budget."""


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item: pytest.Item) -> Iterator[None]:
    limit = float(item.config.getini("timeout") or 0)
    if limit > 0:
        faulthandler.dump_traceback_later(limit + HANG_EXIT_AFTER, exit=True, file=sys.__stderr__)
    try:
        yield
    finally:
        if limit > 0:
            faulthandler.cancel_dump_traceback_later()


def pytest_configure(config: pytest.Config) -> None:
    if config.getoption("numprocesses", None) and not hasattr(config, "workerinput"):
        _glib_warnings_can_reach_the_controller()


def _glib_warnings_can_reach_the_controller() -> None:
    """A GLib warning a test caught (a GTK critical) is of class ``gobject.Warning``, whose module
    PyGObject keeps as a guard that refuses every name: pytest-xdist's controller, which re-imports a
    worker's warning class by its module's name to report it, ended the whole run with an internal error
    on it. The guard is given that one class; every other name still fails as PyGObject means it to."""
    from gi import _gi

    importlib.import_module("gobject").Warning = _gi.Warning


def pytest_terminal_summary(terminalreporter, exitstatus: int, config: pytest.Config) -> None:  # type: ignore[no-untyped-def]
    screenshots = Path(os.environ["RTMU_SCREENSHOTS"])
    if screenshots.is_dir():
        shots = sorted(screenshots.glob("*.png"))
        terminalreporter.write_line(f"rtmu gui: {len(shots)} screenshots in {screenshots}")


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """The screenshot folder stays only when it holds pictures (removed by the run that named it)."""
    screenshots = Path(os.environ["RTMU_SCREENSHOTS"])
    if _NAMED_SCREENSHOTS and screenshots.is_dir() and not any(screenshots.iterdir()):
        with contextlib.suppress(OSError):
            screenshots.rmdir()


@pytest.fixture(scope="session")
def built_dists(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """The sdist and wheel ``python -m build`` makes of this checkout, built once per run (``run_once``:
    also when the run is spread over workers)."""
    sdist, wheel = run_once(tmp_path_factory, "dists", lambda folder: list(build_dists(folder)))
    return sdist, wheel


@pytest.fixture
def german() -> Iterator[None]:
    """The window's and the CLI's words in German for one test (English again after it)."""
    from rtmu.base import i18n

    i18n.use(["de"])
    try:
        yield
    finally:
        i18n.use(["en"])

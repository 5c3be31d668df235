"""A real window manager (openbox) on an X server of a test's own: one way to start it, for every test.

Why one module: two fixtures each started openbox their own way, and one of them on an Xvfb that
reset itself whenever its last client left. Under load the fixture's first ``xprop`` could come and
go before openbox had connected; the server reset under openbox's start and openbox exited with
status 1 (seen twice in CI). The screen here never resets (``-noreset``), openbox's own words are
kept, and an openbox that dies while starting is started again — what the fixture needs is a managed
screen, not openbox's first attempt.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager

import pytest

from .conftest import _spawn_xvfb, _terminate
from .process import wait

OPENBOX = shutil.which("openbox")
CI = os.environ.get("CI", "").lower() in ("true", "1")  # as in conftest: on CI a missing tool fails
STARTS = 3


def require_openbox(why: str) -> None:
    """Skip (fail on CI) when openbox is not installed; ``why`` says what needs it."""
    if OPENBOX is None:
        message = f"openbox is needed to {why} (apt-get install openbox)"
        if CI:
            pytest.fail(f"CI=true but {message}", pytrace=False)
        pytest.skip(message)


def managing(env: dict[str, str]) -> bool:
    """Whether a window manager has announced itself on the root window of ``env``'s display."""
    out = subprocess.run(
        ["xprop", "-root", "_NET_SUPPORTING_WM_CHECK"], env=env, capture_output=True, text=True, timeout=15
    ).stdout
    return "window id" in out


@contextmanager
def managed_screen(size: str) -> Iterator[dict[str, str]]:
    """An Xvfb of ``size`` (e.g. ``1024x768``) with openbox managing it: the environment for X
    clients on it. Both are ended afterwards."""
    assert OPENBOX is not None
    xvfb, display = _spawn_xvfb(size)
    if display is None:
        pytest.fail(f"an Xvfb of {size} did not start")
    env = dict(os.environ, DISPLAY=display)
    wm: subprocess.Popen[bytes] | None = None
    try:
        wm = _start_openbox(env)
        yield env
    finally:
        _terminate(wm)
        _terminate(xvfb)


def _start_openbox(env: dict[str, str]) -> subprocess.Popen[bytes]:
    """openbox managing ``env``'s display; started again (up to ``STARTS`` times) if it exits while
    starting. Fails with what openbox said when it never manages the screen."""
    said = ""
    for _ in range(STARTS):
        with tempfile.TemporaryFile() as log:
            wm = subprocess.Popen([OPENBOX or "openbox"], env=env, stdout=log, stderr=log)

            def running_and_managing(wm: subprocess.Popen[bytes] = wm) -> bool:
                return wm.poll() is not None or managing(env)

            try:
                wait(running_and_managing, 15, "openbox to manage the screen")
            except AssertionError:
                _terminate(wm)  # alive but never managing: not left behind
                raise
            if wm.poll() is None:
                return wm
            log.seek(0)
            said = log.read().decode(errors="replace")
    pytest.fail(f"openbox exited {STARTS} times while starting; it said:\n{said[-2000:]}", pytrace=False)

"""Saving a remembered password must not freeze the window: the keyring may block (D-Bus, unlock prompt)."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import pytest

from rtmu.settings.store import Profile
from simulators import running

from .harness import OFFICE_MAP, Gui, LoopProbe, pump


class BlockingSecrets:
    """A keyring whose ``set`` blocks until the test lets it go."""

    available = True

    def __init__(self) -> None:
        self.release = threading.Event()
        self.entered = threading.Event()
        self.stored: dict[str, str] = {}
        self.thread: str | None = None

    def get(self, profile: Profile) -> str | None:
        return self.stored.get(profile.name)

    def set(self, profile: Profile, password: str) -> None:
        self.thread = threading.current_thread().name
        self.entered.set()
        self.release.wait(5)
        self.stored[profile.name] = password


@pytest.fixture
def gui(request: pytest.FixtureRequest, screenshots: Path) -> Iterator[Gui]:
    with running(map_path=OFFICE_MAP, seed=1) as sim:
        g = Gui.start(screenshots, request.node.name, "127.0.0.1", sim.port, connect=False)
        try:
            yield g
        finally:
            g.close()


def test_a_blocking_keyring_does_not_stop_the_main_loop(gui: Gui) -> None:
    secrets = BlockingSecrets()
    gui.app.secrets = secrets  # type: ignore[assignment]
    profile = replace(gui.window.controller.profile, user="alice", remember_password=True)
    try:
        gui.app.profile_saved(profile, "s3cret")  # returns although the keyring blocks
        pump(secrets.entered.is_set, 5, "the keyring call to start")
        probe = LoopProbe()
        pump(lambda: probe.beats >= 3, 5, "the main loop to keep running")
        probe.close()
        assert secrets.thread != threading.current_thread().name
        assert profile.name not in secrets.stored
    finally:
        secrets.release.set()
    pump(lambda: secrets.stored.get(profile.name) == "s3cret", 5, "the password to be stored")
    gui.shot("saved")

"""The simulator as a test fixture, written once.

A module says which robot it talks to and gets a fixture of that name::

    sim = simulator(map_path=OFFICE, camera=False)          # one simulator for each test
    aram = simulator(scope="module", profile="aram")         # one for the whole module
    sim = simulator(users=("alice secret1 all",))            # logging in needs a password

Every other keyword is a :class:`~rtmu.sim.SimConfig` field; the port is always a free one on
127.0.0.1. A fixture that needs another fixture (the robot's files folder, a display, a second
simulator) opens :func:`running` in its own body.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Literal

import pytest

from rtmu.sim import SimConfig, SimThread


@contextmanager
def running(**config: Any) -> Iterator[SimThread]:
    """The simulator with these :class:`SimConfig` fields on a free loopback port, stopped (clients get
    SHUTDOWN) when the block ends."""
    with SimThread(SimConfig(port=0, **config)) as sim:
        yield sim


def users_file(folder: Path, *users: str) -> Path:
    """ARIA's user-info file in ``folder``: one ``NAME PASSWORD GROUPS`` line a user."""
    path = folder / "users.txt"
    path.write_text("UserInfoVersion1\n" + "".join(f"user {line}\n" for line in users))
    return path


def simulator(
    *, scope: Literal["function", "module"] = "function", users: Sequence[str] = (), **config: Any
) -> Callable[..., Iterator[SimThread]]:
    """A pytest fixture that serves one simulator with ``config`` to each test (``scope="module"``: to
    the whole module). ``users``: log-ins need these users' passwords (:func:`users_file`); none: anyone
    may log in, as ``SimConfig`` has it. The fixture takes the name it is assigned to."""

    @pytest.fixture(scope=scope)
    def fixture(tmp_path_factory: pytest.TempPathFactory) -> Iterator[SimThread]:
        extra = {"users_path": users_file(tmp_path_factory.mktemp("users"), *users)} if users else {}
        with running(**config, **extra) as sim:
            yield sim

    return fixture

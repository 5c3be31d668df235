"""A window's robot session (through the fleet, recording on) against the simulator over loopback."""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from client.fakes import FakeView
from client.uiqueue import UiQueue
from rtmu.client.link import Opener
from rtmu.client.session_config import SessionConfig
from rtmu.fleet.sessions import Fleet, RobotSession
from rtmu.model.observables import Phase
from rtmu.package_data import project_map
from rtmu.settings.store import Profile, RecordingSettings
from rtmu.sim import SimConfig, SimThread
from rtmu.values.state import StateChange

ARENA = project_map("arena.map")


@contextmanager
def recorded_session(
    directory: Path,
    *,
    sim: SimConfig | None = None,
    spy: list[StateChange] | None = None,
    config: SessionConfig | None = None,
    opener: Opener | None = None,
) -> Iterator[tuple[RobotSession, UiQueue, FakeView, SimThread]]:
    """A connected session recording into ``directory``; ``spy`` gets every change the session published."""
    with SimThread(sim or SimConfig(port=0, map_path=ARENA, seed=1)) as server:
        ui = UiQueue()
        fleet = Fleet()
        profile = Profile("lab", host="127.0.0.1", port=server.port)
        session = fleet.open(
            post=ui.post,
            config=config or SessionConfig(),
            profile=profile,
            recording=RecordingSettings(directory=str(directory)),
            opener=opener,
        )
        if spy is not None:
            tap = session.runner.on_publish
            assert tap is not None, "the recorder taps what the session publishes"

            def both(change: StateChange) -> None:
                spy.append(change)
                tap(change)

            session.runner.on_publish = both
        view = FakeView()
        session.attach_view(view)
        try:
            session.controller.connect()
            ui.wait_for(lambda: session.state.connection.value.phase is Phase.CONNECTED, timeout=10)
            yield session, ui, view, server
        finally:
            fleet.close()
            ui.drain()


def hold(ui: UiQueue, session: RobotSession, direction: str, seconds: float) -> None:
    """Hold a drive key as the window does (press, renew at 10 Hz), then release it."""
    session.controller.press(direction)
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        session.controller.tick()
        ui.drain()
        time.sleep(0.1)
    session.controller.release(direction)
    ui.drain()

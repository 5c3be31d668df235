"""Two robot sessions in one process, each against its own simulator over loopback.

Driving one never moves the other; stopping or closing the fleet stops both before
either server's own 2 s watchdog would; closing a session unhooks it completely.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import ExitStack, contextmanager

from rtmu.client.session import SessionConfig
from rtmu.fleet.sessions import Fleet, RobotSession
from rtmu.model.observables import Phase
from rtmu.package_data import project_map
from rtmu.settings.store import Profile
from rtmu.sim import SimConfig, SimThread

from .fakes import FakeView
from .uiqueue import UiQueue

ARENA = project_map("arena.map")


@contextmanager
def two_robots() -> Iterator[tuple[Fleet, UiQueue, list[tuple[RobotSession, SimThread]]]]:
    with ExitStack() as stack:
        ui = UiQueue()
        fleet = Fleet()
        pairs = []
        for name in ("left", "right"):
            sim = stack.enter_context(SimThread(SimConfig(port=0, map_path=ARENA, seed=1)))
            profile = Profile(name, host="127.0.0.1", port=sim.port)
            session = fleet.open(post=ui.post, config=SessionConfig(fetch_map=False), profile=profile)
            session.controller.connect()
            pairs.append((session, sim))
        stack.callback(fleet.close)
        for session, _sim in pairs:
            ui.wait_for(lambda s=session: s.state.connection.value.phase is Phase.CONNECTED, timeout=10)
        yield fleet, ui, pairs


def hold(ui: UiQueue, sessions: list[RobotSession], direction: str, seconds: float) -> None:
    """Hold a drive key on each of ``sessions`` as the window would: press, then tick at 10 Hz."""
    for session in sessions:
        session.controller.press(direction)
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        for session in sessions:
            session.controller.tick()
        ui.drain()
        time.sleep(0.1)


def wait_stopped(sims: list[SimThread]) -> None:
    """Each simulator reaches its stop mode (only a ``stop`` request sets it) within 1 s: half its watchdog.

    What is waited for has already left this process; the servers' threads may not have read it yet.
    """
    deadline = time.monotonic() + 1.0
    for sim in sims:
        while sim.call(lambda s=sim: s.server.robot.mode_name) != "stop":
            assert time.monotonic() < deadline, "a robot was not stopped"
            time.sleep(0.02)


def drives(sim: SimThread) -> int:
    return int(sim.call(lambda: sim.server.robot.ratio_drives_received))


def test_driving_one_robot_never_moves_the_other() -> None:
    with two_robots() as (fleet, ui, pairs):
        (left, left_sim), (right, right_sim) = pairs
        assert fleet.selected.value is right and len(fleet) == 2
        start_right = right_sim.snapshot()
        hold(ui, [left], "forward", 1.0)
        assert drives(left_sim) > 0
        assert left_sim.snapshot().vel > 0, "the driven robot moves"
        assert drives(right_sim) == 0, "the other robot got a drive command"
        right_now = right_sim.snapshot()
        assert right_now.vel == 0 and (right_now.x, right_now.y) == (start_right.x, start_right.y)
        ui.wait_for(lambda: left.state.robot.value.vel > 0)
        assert right.state.robot.value.vel == 0, "the other session's state moved"
        left.controller.release("forward")


def test_stop_all_stops_every_robot_before_any_watchdog() -> None:
    with two_robots() as (fleet, ui, pairs):
        sessions = [session for session, _sim in pairs]
        hold(ui, sessions, "forward", 0.6)
        for _session, sim in pairs:
            assert sim.call(lambda s=sim: s.server.robot.mode_name) == "ratioDrive"
        watchdog = [sim.call(lambda s=sim: s.server.robot.watchdog_stops) for _s, sim in pairs]
        assert fleet.stop_all(wait=1.0), "a stop did not leave the process in time"
        wait_stopped([sim for _s, sim in pairs])
        assert [sim.call(lambda s=sim: s.server.robot.watchdog_stops) for _s, sim in pairs] == watchdog
        for session in sessions:
            assert session.controller.held == frozenset(), "held keys survive stop_all"


def test_closing_the_fleet_stops_both_and_unhooks_everything() -> None:
    with two_robots() as (fleet, ui, pairs):
        sessions = [session for session, _sim in pairs]
        views = []
        for session in sessions:
            view = FakeView()
            session.attach_view(view)
            views.append(view)
        hold(ui, sessions, "forward", 0.6)
        watchdog = [sim.call(lambda s=sim: s.server.robot.watchdog_stops) for _s, sim in pairs]
        fleet.close()
        wait_stopped([sim for _s, sim in pairs])
        assert [sim.call(lambda s=sim: s.server.robot.watchdog_stops) for _s, sim in pairs] == watchdog
        for session, _sim in pairs:
            assert session.closed
            assert not session.runner._thread.is_alive(), "the network thread outlived close()"
            assert session.runner.on_notice is None
            assert not session.state.connection._observers, "the controller still observes the model"
        assert len(fleet) == 0 and fleet.selected.value is None
        # Nothing reaches the old views any more, whatever the model does now.
        seen = [len(view.notices) for view in views]
        for session in sessions:
            session.state.connection.set(session.state.connection.value.__class__(Phase.FAILED, error="x"))
        assert [len(view.notices) for view in views] == seen

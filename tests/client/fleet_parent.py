"""A driving process for the guardian tests: the window's fleet and its ONE guardian, without GTK.

``python tests/client/fleet_parent.py NAME=PORT …`` builds a :class:`~rtmu.fleet.sessions.Fleet` of
those robots with a :class:`~rtmu.guardian.shared.SharedGuardian` (as the window does), connects them
and prints ``ready <guardian pid>``. Its main thread is the "UI thread": it runs what the network
threads post, and what the window's timers do (``controller.tick`` every 100 ms, the guardian's UI
heartbeat every 40 ms). Commands, one per line on stdin, each answered by one line:

* ``select NAME`` → ``selected NAME``
* ``press DIR`` → ``pressed`` or ``refused <the controller's words>``; ``release DIR`` → ``released``
* ``armed NAME`` → ``armed NAME`` once the guardian is armed for NAME (``not-armed NAME <state>``
  after 20 s)
* ``close`` → ``closed`` (the fleet closed: every robot stopped, the guardian told goodbye)
"""

from __future__ import annotations

import contextlib
import queue
import sys
import threading
import time
from collections.abc import Callable, Mapping

from rtmu.base.notices import Notice
from rtmu.client.roster import DirectRoster, RobotEndpoint
from rtmu.client.session import SessionConfig
from rtmu.control.commands import CommandState
from rtmu.fleet.sessions import Fleet, RobotSession, robot_profile
from rtmu.guardian.handle import BEAT_PERIOD
from rtmu.guardian.shared import SharedGuardian
from rtmu.settings.store import Profile

TICK = 0.1


class Said:
    """The controllers' View: keeps the last notice (a refusal's words)."""

    def __init__(self) -> None:
        self.last = ""

    def notify(self, notice: Notice) -> None:
        self.last = notice.text

    def commands_changed(self, states: Mapping[str, CommandState]) -> None:
        pass

    def ask_password(self, profile: Profile, answer: Callable[[str | None], None]) -> None:
        answer("")

    def open_dialog(self, name: str) -> None:
        pass


def main(argv: list[str]) -> int:
    ui: queue.Queue[Callable[[], object]] = queue.Queue()
    endpoints = [RobotEndpoint(n, "127.0.0.1", int(p)) for n, p in (a.split("=") for a in argv)]
    fleet = Fleet(guardian=SharedGuardian())
    said = Said()

    def make(endpoint: RobotEndpoint) -> RobotSession:
        session = RobotSession(
            fleet.operator,
            post=ui.put,
            config=SessionConfig(fetch_map=False),
            profile=robot_profile(Profile("fleet"), endpoint),
            guardian=fleet.guardian,
        )
        session.attach_view(said)
        return session

    fleet.follow(DirectRoster(endpoints), make)
    waiting: list[tuple[float, str]] = []
    running = True

    def out(line: str) -> None:
        print(line, flush=True)

    def command(line: str) -> None:
        nonlocal running
        word, _, arg = line.strip().partition(" ")
        selected = fleet.selected.value
        if word == "select":
            fleet.select_named(arg)
            out(f"selected {arg}")
        elif word == "press" and selected is not None:
            said.last = ""
            selected.controller.press(arg)
            out("pressed" if selected.controller.held else f"refused {said.last}")
        elif word == "release" and selected is not None:
            selected.controller.release(arg)
            out("released")
        elif word == "armed":
            waiting.append((time.monotonic() + 20.0, arg))
        elif word == "close":
            fleet.close()
            out("closed")
            running = False

    def read() -> None:
        for line in sys.stdin:
            ui.put(lambda line=line: command(line))

    threading.Thread(target=read, daemon=True).start()
    announced = False
    next_tick = next_beat = time.monotonic()
    while running:
        with contextlib.suppress(queue.Empty):
            ui.get(timeout=0.01)()
        now = time.monotonic()
        if not announced and len(fleet) == len(endpoints) and all(s.controller.connected for s in fleet):
            announced = True
            out(f"ready {fleet.guardian.pid if fleet.guardian else 0}")
        for entry in list(waiting):
            deadline, name = entry
            session = fleet.named(name)
            seat = session.seat if session is not None else None
            if seat is not None and seat.armed_for_it:
                waiting.remove(entry)
                out(f"armed {name}")
            elif now > deadline:
                waiting.remove(entry)
                out(f"not-armed {name} {seat.state.value if seat else 'no seat'}")
        if now >= next_tick:  # the window's 10 Hz timer: renew held drives
            next_tick = now + TICK
            for session in fleet:
                session.controller.tick()
        if now >= next_beat:  # the window's 40 ms timer: the UI thread's heartbeat
            next_beat = now + BEAT_PERIOD
            if fleet.selected.value is not None:
                fleet.selected.value.runner.ui_heartbeat()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

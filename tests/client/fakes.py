"""A view that records what the controller tells it, and a link that records what it is asked to do.

The link is not a protocol mock: it holds the real :class:`DriveLease` and only
stands in for the network thread, so the controller's own rules can be tested
one by one. End-to-end tests use the real ``ClientRunner`` against the simulator.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

from rtmu.base.notices import Kind, Level, Notice
from rtmu.client.lease import DriveLease
from rtmu.control.commands import CommandState
from rtmu.settings.store import Profile


class FakeView:
    def __init__(self) -> None:
        self.notices: list[tuple[Level, str]] = []
        self.kinds: list[Kind] = []
        self.states: dict[str, CommandState] = {}
        self.state_calls = 0
        self.password_asks: list[tuple[Profile, Callable[[str | None], None]]] = []

    def notify(self, notice: Notice) -> None:
        self.notices.append((notice.level, notice.text))
        self.kinds.append(notice.kind)

    def commands_changed(self, states: Mapping[str, CommandState]) -> None:
        self.state_calls += 1
        self.states.update(states)

    def ask_password(self, profile: Profile, answer: Callable[[str | None], None]) -> None:
        self.password_asks.append((profile, answer))

    def texts(self) -> list[str]:
        return [t for _, t in self.notices]


class RecordingLink:
    def __init__(self, clock: Callable[[], float]) -> None:
        self.lease = DriveLease(clock=clock)
        self.on_notice: Callable[[Notice], None] | None = None
        self.calls: list[tuple[object, ...]] = []
        self.blocking: list[tuple[Callable[[], object], Callable[[object], None]]] = []

    def connect(self, host: str, port: int, user: str = "", password: str = "", **kw: object) -> None:
        self.calls.append(("connect", host, port, user, password, kw.get("profile")))

    def disconnect(self) -> None:
        self.calls.append(("disconnect",))

    def stop(self) -> None:
        self.calls.append(("stop",))

    def command(self, name: str, *args: object) -> None:
        self.calls.append(("command", name, *args))

    def request_image(self) -> None:
        self.calls.append(("request_image",))

    def set_safe_drive(self, on: bool) -> None:
        self.calls.append(("set_safe_drive", on))

    def goto_goal(self, name: str) -> None:
        self.calls.append(("goto_goal", name))

    def goto_pose(self, x: float, y: float, th: float | None = None) -> None:
        self.calls.append(("goto_pose", x, y, th))

    def home(self) -> None:
        self.calls.append(("home",))

    def dock(self) -> None:
        self.calls.append(("dock",))

    def tour_goals(self) -> None:
        self.calls.append(("tour_goals",))

    def localize(self, x: float, y: float, th: float) -> None:
        self.calls.append(("localize", x, y, th))

    def run_blocking(self, fn: Callable[[], object], done: Callable[[object], None]) -> None:
        """Like the runner: ``fn`` must not run on the UI (test) thread; :meth:`finish_blocking` runs it."""
        self.calls.append(("run_blocking",))
        self.blocking.append((fn, done))

    def finish_blocking(self) -> list[int]:
        """Run the pending blocking calls on another thread, then deliver the answers here."""
        import threading

        ran: list[int] = []
        jobs, self.blocking = self.blocking, []
        for fn, done in jobs:
            result: list[object] = []

            def work(fn: Callable[[], object] = fn, result: list[object] = result) -> None:
                ran.append(threading.get_ident())
                result.append(fn())

            worker = threading.Thread(target=work)
            worker.start()
            worker.join(5)
            done(result[0] if result else None)
        return ran

    def names(self) -> list[object]:
        return [c[0] for c in self.calls]

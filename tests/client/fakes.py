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
from rtmu.values import intents
from rtmu.values.intents import Intent
from rtmu.values.target import Target


class FakeView:
    def __init__(self) -> None:
        self.notices: list[tuple[Level, str]] = []
        self.kinds: list[Kind] = []
        self.states: dict[str, CommandState] = {}
        self.state_calls = 0
        self.password_asks: list[tuple[Profile, Callable[[str | None], None]]] = []
        self.drives = 0
        """Drives begun (``driving`` calls): a window starts its lease-renewal timer on each."""

    def notify(self, notice: Notice) -> None:
        self.notices.append((notice.level, notice.text))
        self.kinds.append(notice.kind)

    def commands_changed(self, states: Mapping[str, CommandState]) -> None:
        self.state_calls += 1
        self.states.update(states)

    def ask_password(self, profile: Profile, answer: Callable[[str | None], None]) -> None:
        self.password_asks.append((profile, answer))

    def driving(self) -> None:
        self.drives += 1

    def texts(self) -> list[str]:
        return [t for _, t in self.notices]


class RecordingLink:
    def __init__(self, clock: Callable[[], float]) -> None:
        self.lease = DriveLease(clock=clock)
        self.on_notice: Callable[[Notice], None] | None = None
        self.calls: list[tuple[object, ...]] = []
        self.targets: list[Target] = []
        self.blocking: list[tuple[Callable[[], object], Callable[[object], None]]] = []

    def connect(self, target: Target) -> None:
        self.targets.append(target)
        self.calls.append(("connect", target.host, target.port, target.user, target.password, target.profile))

    def disconnect(self) -> None:
        self.calls.append(("disconnect",))

    def send(self, intent: Intent) -> None:
        """Every intent the controller lets through, recorded in the shape the rules' tests read."""
        self.calls.append(_call(intent))

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


def _call(intent: Intent) -> tuple[object, ...]:
    match intent:
        case intents.Stop():
            return ("stop",)
        case intents.TurnBy(degrees=d):
            return ("command", "turnByAngle", d)
        case intents.MoveDistance(mm=mm):
            return ("command", "moveDist", mm)
        case intents.RequestPicture():
            return ("request_image",)
        case intents.SetSafeDrive(on=on):
            return ("set_safe_drive", on)
        case intents.GotoGoal(name=name):
            return ("goto_goal", name)
        case intents.GotoPose(x=x, y=y, th=th):
            return ("goto_pose", x, y, th)
        case intents.GoHome():
            return ("home",)
        case intents.Dock():
            return ("dock",)
        case intents.TourGoals():
            return ("tour_goals",)
        case intents.Localize(x=x, y=y, th=th):
            return ("localize", x, y, th)
    return ("send", intent)

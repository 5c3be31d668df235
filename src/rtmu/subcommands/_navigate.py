"""What ``rtmu goto / home / dock / localize`` share: send one navigation command, follow it to its end.

The server drives (ARNL); we only read its words (``Going to Lab B`` → ``Arrived at Lab B`` or
``Failed to get to Lab B because robot lost``, ``Docked``) through :mod:`rtmu.client.nav_status`,
print each new one (escaped: server text), and exit with what they say. Ctrl-C, SIGTERM, SIGHUP
(every ending signal) and giving up after ``--limit`` send ``stop`` before the command ends: the
robot does not drive on for a command nobody is watching. ``--no-wait`` sends and leaves it driving.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_OK, EXIT_TIMEOUT
from ..base.i18n import N_, Said, _, number
from ..base.textsafe import visible
from ..base.units import metres
from ..client.errors import ClientError
from ..client.nav_status import LOST, NAV_MODES, NavReading, path_remaining, read_motion
from ..protocol.errors import ProtocolError
from ..protocol.payloads import Payload, Side, decode_payload
from ..protocol.payloads.drive import RatioDrive
from ..protocol.payloads.ld import DockInfo
from ..protocol.payloads.navigation import LocalizationState, LocState, PlannedPath
from ..protocol.payloads.robot import ModeInfo, Update, UpdateNumbers, UpdateStrings
from ..values.state import NavOutcome
from ._common import Interrupted, current_interrupts, print_json, signal_name
from ._nav_args import EXIT_NAV_CANCELLED, EXIT_NAV_FAILED, EXIT_NAV_LOST

if TYPE_CHECKING:
    from ..client.call_values import Packet
    from ..client.connection import AriaClient

SETTLE = 1.5
"""After this many seconds an outcome the server already showed before our command counts as the
answer (it repeated it: e.g. a second ``goto`` to an unreachable goal fails with the same words)."""
STATUS_MS = 250
PATH_MS = 1000
DISTANCE_STEP_MM = 1000.0
"""Print the distance left when it changed by this much (and no oftener than DISTANCE_EVERY s)."""
DISTANCE_EVERY = 2.0


def stop_robot(client: AriaClient) -> None:
    """``stop`` (zero ``ratioDrive`` where there is no ``stop``); never raises: we are ending."""
    with contextlib.suppress(ClientError):
        if client.supports("stop"):
            client.send("stop")
        elif client.supports("ratioDrive"):
            client.send(RatioDrive(0.0, 0.0, 0.0))


@dataclass(frozen=True)
class Expect:
    """Which outcome answers our command: ``target`` as the server names it (a goal, ``point``,
    ``home``) for an arrival, or ``docked`` for the dock."""

    target: str = ""
    docked: bool = False

    def answers(self, r: NavReading) -> bool:
        if r.phase is NavOutcome.FAILED:
            return True
        if r.phase is NavOutcome.DOCKED:
            return self.docked
        return r.phase is NavOutcome.ARRIVED and not self.docked and r.target == self.target


class _Watch:
    """The server's words (and pose, path, dock state) as they come, on the command's loop."""

    def __init__(self) -> None:
        import asyncio

        self.status = ""
        self.mode_name = ""
        self.dock_state: str | None = None
        self.pose: tuple[float, float, float] | None = None
        self.path: tuple[tuple[int, int], ...] = ()
        self.loc: LocState | None = None
        self.navigated = False
        """The server entered a navigation mode since this was last cleared (``getModeInfo`` is sent
        on each change: a drive that started and was stopped between two status packets, or before
        the loop looked, still shows)."""
        self.changed = asyncio.Event()

    def reading(self) -> NavReading:
        return read_motion(self.status, self.mode_name, self.dock_state)

    @property
    def navigation_ended(self) -> bool:
        """A navigation mode began since :attr:`navigated` was cleared, and the server has left it."""
        return self.navigated and self.mode_name not in NAV_MODES

    def handler(self, apply: Callable[[Any], None]) -> Callable[[Packet], None]:
        def on_packet(packet: Packet) -> None:
            try:
                value = decode_payload(packet.name, Side.REPLY, packet.payload)
            except ProtocolError:
                return  # one bad packet: the next one will do
            apply(value)
            self.changed.set()

        return on_packet

    def on_strings(self, s: Any) -> None:
        if isinstance(s, UpdateStrings):
            self.status = s.status
        elif isinstance(s, Update):
            self.status = s.status
            self._numbers(s.numbers)

    def on_numbers(self, n: Any) -> None:
        if isinstance(n, UpdateNumbers):
            self._numbers(n)

    def _numbers(self, n: UpdateNumbers) -> None:
        self.pose = (float(n.x), float(n.y), float(n.th))

    def on_mode(self, m: Any) -> None:
        if isinstance(m, ModeInfo):
            self.mode_name = m.mode_name
            self.navigated = self.navigated or m.mode_name in NAV_MODES

    def on_path(self, p: Any) -> None:
        if isinstance(p, PlannedPath):
            self.path = p.points

    def on_dock(self, d: Any) -> None:
        if isinstance(d, DockInfo):
            self.dock_state = d.state_label

    def on_loc(self, loc: Any) -> None:
        if isinstance(loc, LocState):
            self.loc = loc

    def subscribe(self, client: AriaClient) -> None:
        if client.supports("updateStrings"):
            client.request("updateStrings", STATUS_MS, self.handler(self.on_strings))
        elif client.supports("update"):
            client.request("update", STATUS_MS, self.handler(self.on_strings))
        if client.supports("updateNumbers"):
            client.request("updateNumbers", STATUS_MS * 2, self.handler(self.on_numbers))
        if client.supports("getModeInfo"):
            client.request("getModeInfo", -1, self.handler(self.on_mode))
        if client.supports("getPath"):
            client.request("getPath", PATH_MS, self.handler(self.on_path))
        if client.supports("dockInfo"):
            client.request("dockInfo", STATUS_MS * 2, self.handler(self.on_dock))
        if client.supports("getLocState"):
            client.request("getLocState", STATUS_MS, self.handler(self.on_loc))

    async def first(self, client: AriaClient, timeout: float) -> None:
        """Wait (bounded) for the first status, so what the server said *before* our command is known."""
        import asyncio

        if not (client.supports("updateStrings") or client.supports("update")):
            return
        with contextlib.suppress(TimeoutError):
            async with asyncio.timeout(timeout):
                while not self.status:
                    self.changed.clear()
                    await self.changed.wait()


def _say(args: argparse.Namespace, obj: dict[str, Any], line: str) -> None:
    if args.json:
        print_json(obj)
    else:
        print(line, flush=True)


def _pose_fields(watch: _Watch) -> dict[str, Any]:
    if watch.pose is None:
        return {"x": None, "y": None, "th": None}
    x, y, th = watch.pose
    return {"x": x, "y": y, "th": th}


async def navigate(client: AriaClient, args: argparse.Namespace, payload: Payload, expect: Expect) -> int:
    """Send ``payload`` and follow the server's words until ``expect`` answers; the exit code."""
    watch = _Watch()
    watch.subscribe(client)
    await watch.first(client, args.timeout)
    before = watch.reading()
    watch.navigated = False  # (a navigation going before ours shows in the status it sends)
    client.send(payload)
    if args.no_wait:
        _say(args, {"sent": type(payload).DATA_NAME}, _("sent {name}").format(name=type(payload).DATA_NAME))
        await client.flush()
        return EXIT_OK
    return await _follow(client, args, watch, before, expect)


async def _follow(
    client: AriaClient, args: argparse.Namespace, watch: _Watch, before: NavReading, expect: Expect
) -> int:
    import asyncio

    loop = asyncio.get_running_loop()
    sent_at = loop.time()
    shown = ""
    seen_going = False
    distance_at, distance_shown = 0.0, None
    interrupts = current_interrupts()
    try:
        async with asyncio.timeout(args.limit):
            while True:
                r = watch.reading()
                now = loop.time()
                if r.text and r.text != shown and (r.text != before.text or now - sent_at >= SETTLE):
                    shown = r.text
                    _say(args, {"status": r.text, "phase": r.phase.value}, visible(r.text))
                if r.phase is NavOutcome.GOING:
                    seen_going = True
                    left = path_remaining(*watch.pose[:2], watch.path) if watch.pose and watch.path else None
                    if (
                        left is not None
                        and now - distance_at >= DISTANCE_EVERY
                        and (distance_shown is None or abs(left - distance_shown) >= DISTANCE_STEP_MM)
                    ):
                        distance_at, distance_shown = now, left
                        _say(
                            args,
                            {"remaining_mm": round(left)},
                            _("  {distance} to go").format(distance=metres(left)),
                        )
                elif r.finished and expect.answers(r):
                    fresh = seen_going or r.text != before.text or now - sent_at >= SETTLE
                    if fresh:
                        return _outcome(args, watch, r)
                elif (seen_going or watch.navigation_ended) and (r.phase is NavOutcome.NONE or r.finished):
                    # Stopped, driven, or finished somewhere else: someone took the robot over (perhaps
                    # before a status saying "Going to" reached us: the mode's change says it went).
                    return _ended(args, watch, r, "cancelled", EXIT_NAV_CANCELLED)
                watch.changed.clear()
                with contextlib.suppress(TimeoutError):
                    async with asyncio.timeout(SETTLE / 3):
                        await watch.changed.wait()
    except TimeoutError:
        stop_robot(client)
        await client.flush()
        line = _("no outcome in time: the robot was stopped")
        _say(args, {"outcome": "timeout", **_pose_fields(watch)}, line)
        print(
            _("rtmu {subcommand}: no outcome within {limit:g} s; stop sent").format(
                subcommand=args.subcommand, limit=args.limit
            ),
            file=sys.stderr,
        )
        return EXIT_TIMEOUT
    except asyncio.CancelledError:
        signum = interrupts.take()
        if signum is None:
            raise
        stop_robot(client)  # the stop first, before anything is printed
        await client.flush()
        if args.json:  # the promised last line: how it ended, and where the robot was
            print_json({"outcome": "interrupted", "signal": signal_name(signum), **_pose_fields(watch)})
        raise Interrupted(signum, Said(N_("the robot was stopped"))) from None


def _outcome(args: argparse.Namespace, watch: _Watch, r: NavReading) -> int:
    if r.phase is NavOutcome.FAILED:
        lost = r.reason == LOST
        code = EXIT_NAV_LOST if lost else EXIT_NAV_FAILED
        return _ended(args, watch, r, "failed", code)
    return _ended(args, watch, r, r.phase.value, EXIT_OK)


def _ended(args: argparse.Namespace, watch: _Watch, r: NavReading, outcome: str, code: int) -> int:
    obj = {"outcome": outcome, "text": r.text, "reason": r.reason, **_pose_fields(watch)}
    if args.json:
        print_json(obj)
    elif code != EXIT_OK:
        sentence = r.sentence()  # a failure's reason of RTMU's own is a Said; the server's words as sent
        why = (sentence.words() if isinstance(sentence, Said) else sentence) or r.text
        why = why or _("it stopped before arriving")
        print(
            _("rtmu {subcommand}: {visible}").format(subcommand=args.subcommand, visible=visible(why)),
            file=sys.stderr,
        )
    return code


# -- localization ------------------------------------------------------------------------------
async def localize(client: AriaClient, args: argparse.Namespace, payload: Payload) -> int:
    """Send ``localizeToPose``; where ``getLocState`` is listed, wait until it says localized or lost."""
    import asyncio

    watch = _Watch()
    if client.supports("getLocState"):
        client.request("getLocState", STATUS_MS, watch.handler(watch.on_loc))
    client.send(payload)
    if args.no_wait or not client.supports("getLocState"):
        line = (
            _("sent {name}")
            if args.no_wait
            else _("sent {name} (the server offers no getLocState to confirm it)")
        ).format(name="localizeToPose")
        _say(args, {"sent": "localizeToPose"}, line)
        await client.flush()
        return EXIT_OK
    loop = asyncio.get_running_loop()
    sent_at = loop.time()
    seen_initializing = False
    interrupts = current_interrupts()
    try:
        async with asyncio.timeout(args.limit):
            while True:
                loc = watch.loc
                now = loop.time()
                if loc is not None:
                    state = loc.state
                    if state == LocalizationState.INITIALIZING and not seen_initializing:
                        seen_initializing = True
                        _say(args, {"localization": loc.state_label}, _("localizing"))
                    settled = seen_initializing or now - sent_at >= SETTLE
                    if settled and state in (LocalizationState.GOOD, LocalizationState.LOST):
                        good = state == LocalizationState.GOOD
                        obj = {"outcome": "localized" if good else "lost", "score": loc.score_fraction}
                        line = (
                            _("localized (score {score})").format(score=number(loc.score_fraction, 2))
                            if good
                            else _(LOST)
                        )
                        _say(args, obj, line)
                        if not good:
                            print(
                                _("rtmu {subcommand}: the robot is still lost").format(
                                    subcommand=args.subcommand
                                ),
                                file=sys.stderr,
                            )
                        return EXIT_OK if good else EXIT_NAV_LOST
                watch.changed.clear()
                with contextlib.suppress(TimeoutError):
                    async with asyncio.timeout(SETTLE / 3):
                        await watch.changed.wait()
    except TimeoutError:
        _say(args, {"outcome": "timeout"}, _("no answer in time"))
        print(
            _("rtmu {subcommand}: not localized within {limit:g} s").format(
                subcommand=args.subcommand, limit=args.limit
            ),
            file=sys.stderr,
        )
        return EXIT_TIMEOUT
    except asyncio.CancelledError:
        signum = interrupts.take()
        if signum is None:
            raise
        raise Interrupted(signum) from None

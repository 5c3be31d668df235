"""``rtmu drive HOST[:PORT] --trans PCT --rot PCT [--throttle PCT] --seconds S``: drive, then stop.

Sends ``ratioDrive`` every 100 ms for S seconds (ARIA's watchdog stops a robot
that hears nothing for 2 s), then zero ratios and ``stop`` — also on Ctrl-C, SIGTERM,
SIGHUP (the terminal or SSH session went away), SIGQUIT or any error, and on a new connection
when ours was lost while driving — and prints the pose before and after (``--json``: one object
``{"before": STATUS, "after": STATUS, "seconds": S}`` with the keys of ``rtmu status``).
Ctrl-Z (SIGTSTP) stops the robot before the process is suspended, and the drive is not resumed
by ``fg``: it ends there.

A drive asked to move that did not move the robot never exits 0: the same answer as ``rtmu why``
(:mod:`rtmu.client.why`) goes to stderr, read with the status words the server said while we
drove, and the exit code is the cause's (20–39; 35 when the ratios asked for are inside ARIA's
dead zone, which is also said before driving; 39 when nothing RTMU can read explains it). A
login that may not drive gets that answer at once (exit 21); one that may not stop is warned.

After a signal the stop goes out first, then the pose is printed if a status comes
within :data:`AFTER_INTERRUPT` s (``after: unknown`` / ``"after": null`` otherwise; the
JSON object gains ``"interrupted": "SIGINT"``), one line on stderr says so, and the exit
code is 128 + the signal's number as shells report it: 130 Ctrl-C, 143 SIGTERM,
129 SIGHUP, 131 SIGQUIT, 148 Ctrl-Z.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_OK, EXIT_SIGQUIT, EXIT_SIGTSTP, EXIT_USAGE, NETWORK, WHY_DRIVE
from ..base.i18n import N_, Said, _, words
from ..base.textsafe import visible
from ..values.target import Target
from ._common import (
    Interrupted,
    UsageError,
    add_connection_arguments,
    current_interrupts,
    current_password,
    print_json,
    run_with_client,
    signal_name,
)
from ._status import fetch_status, status_line

if TYPE_CHECKING:
    from ..client.call_values import Packet
    from ..client.connection import AriaClient
    from ..client.drive_guard import DriveGuard
    from ..client.why_values import Answer, Facts, Motion
    from ..guardian.handle import GuardianHandle
    from ..protocol.payloads.drive import RatioDrive
    from ..protocol.payloads.robot import UpdateStrings

RESEND = 0.1
MAX_SECONDS = 600.0
SETTLE = 3.0
"""At most this long to wait for the robot to come to rest before printing the final pose."""
AFTER_INTERRUPT = 1.0
"""After a signal, at most this long (stop already sent) for the pose printed as ``after``."""


EXITS = (*NETWORK, EXIT_SIGQUIT, EXIT_SIGTSTP, *WHY_DRIVE)


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "drive",
        help=_("drive for some seconds, then stop"),
        description=_(
            "Drive with ratioDrive for S seconds, then stop; print the pose before and after. "
            "A drive that did not move the robot says why (as rtmu why does) and exits with the cause's code."
        ),
    )
    add_connection_arguments(p)
    p.add_argument(
        "--trans", type=float, default=0.0, metavar="PCT", help=_("−100…100 %% of max speed (+ forward)")
    )
    p.add_argument(
        "--rot", type=float, default=0.0, metavar="PCT", help=_("−100…100 %% of max rotation (+ left)")
    )
    p.add_argument("--throttle", type=float, default=50.0, metavar="PCT", help=_("0…100 %% (default 50)"))
    p.add_argument("--seconds", type=float, required=True, metavar="S", help=f"0…{MAX_SECONDS:g}")
    p.add_argument(
        "--json",
        action="store_true",
        help=_('one object {"before", "after", "seconds"}; asked to move, also "moved" (and "why" if not)'),
    )
    p.set_defaults(handler=handle)


def check(args: argparse.Namespace) -> None:
    for name in ("trans", "rot"):
        value = getattr(args, name)
        if not -100.0 <= value <= 100.0:
            raise UsageError(f"--{name} must be −100…100, not {value:g}")
    if not 0.0 <= args.throttle <= 100.0:
        raise UsageError(f"--throttle must be 0…100, not {args.throttle:g}")
    if not 0.0 < args.seconds <= MAX_SECONDS:
        raise UsageError(f"--seconds must be more than 0 and at most {MAX_SECONDS:g}")


def handle(args: argparse.Namespace) -> int:
    import asyncio

    from ..base.priority import raised_priority
    from ..client.drive_guard import DriveGuard, LinkFault
    from ..client.errors import ClientError
    from ..client.roles import Role
    from ..client.why import diagnose, moved, unexplained
    from ..client.why_gather import gather
    from ..client.why_values import Facts, Motion
    from ..guardian.handle import beat_network
    from ..protocol.payloads.drive import RATIO_ROT_DEAD_ZONE, RATIO_TRANS_DEAD_ZONE, RatioDrive
    from .why import print_answer

    async def body(client: AriaClient) -> int:
        # where allowed: the loop that resends, watches the link and stops runs on time (given back after:
        # the caller's thread goes on, e.g. a script calling rtmu's main more than once)
        with raised_priority():
            return await drive_body(client)

    async def drive_body(client: AriaClient) -> int:
        check(args)
        motion = Motion(args.trans, args.rot)
        if not client.supports("ratioDrive"):
            return await refuse(args, client, motion)
        if not client.supports("stop"):
            warning = diagnose(Facts(offers=frozenset(e.name for e in client.datalist), user=client.user))
            for reason in warning.reasons:
                if reason.loud:
                    print(
                        _("rtmu drive: WARNING: {visible}").format(visible=visible(words(reason.sentence()))),
                        file=sys.stderr,
                        flush=True,
                    )
        ratios = RatioDrive(args.trans, args.rot, args.throttle)
        if ratios.in_dead_zone:  # ARIA would take it and not move: say so rather than exit 0 silently
            print(
                _(
                    "rtmu drive: warning: --trans {trans:g} --rot {rot:g} is inside ARIA's dead zone "
                    "(translation up to ±{RATIO_TRANS_DEAD_ZONE:g} %, rotation under "
                    "±{RATIO_ROT_DEAD_ZONE:g} %): the robot will not move"
                ).format(
                    trans=args.trans,
                    rot=args.rot,
                    RATIO_TRANS_DEAD_ZONE=RATIO_TRANS_DEAD_ZONE,
                    RATIO_ROT_DEAD_ZONE=RATIO_ROT_DEAD_ZONE,
                ),
                file=sys.stderr,
                flush=True,
            )
        guardian = await start_guardian(args)
        guard = DriveGuard(client)
        guard.start()  # before the first status fetch, so the link is watched from the start
        before = await fetch_status(client, args.timeout)
        if not args.json:
            print(_("before: {status_line}").format(status_line=status_line(before)), flush=True)
        interrupts = current_interrupts()

        async def before_suspending() -> None:
            stop(client)  # Ctrl-Z: the robot must not drive on while the process sleeps…
            if guardian is not None:
                guardian.disarm()  # our own stop is out: a suspended process is no alarm
            await client.flush()  # …so the stop must have left before it does

        # ``fg`` ends the drive (stop, pose, exit 148) rather than starting the robot again.
        interrupts.on_suspend(before_suspending, end_on_resume=True)
        signum: int | None = None
        beats = asyncio.create_task(beat_network(guardian)) if guardian is not None else None
        if guardian is not None:
            guardian.arm()  # it stops the robot if this process is killed or frozen from here on
        said = StatusWords(client)
        guard.seen_moving = False
        try:
            await drive(client, ratios, args.seconds, held=lambda: interrupts.suspending, guard=guard)
            said.close()  # what the server said while we drove, before our own stop changes it
        except asyncio.CancelledError:
            signum = interrupts.take()
            if signum is None:
                raise
        except LinkFault as fault:
            stop(client)
            await guard.close()
            if client.closed_error is not None:  # our connection is gone: a new one carries the stop
                if await stop_on_a_new_connection(args):
                    raise LinkFault(
                        f"{fault}; zero ratioDrive and stop sent at once on a new connection. Check the "
                        "robot's Wi-Fi and that its server still runs, then drive again."
                    ) from None
                raise LinkFault(
                    f"{fault}; the stop could not be sent (the server's watchdog stops the robot within "
                    "2 s). Check the robot's Wi-Fi and that its server still runs, then drive again."
                ) from None
            await client.flush()
            raise LinkFault(f"{fault}; zero ratioDrive and stop sent at once. {guard.advice()}") from None
        finally:
            stop(client)
            if beats is not None:
                beats.cancel()
            if guardian is not None:
                # Our stop is out: goodbye. If our link is dead, an armed EOF makes the guardian stop.
                if client.closed_error is None:
                    guardian.disarm()
                guardian.close(goodbye=client.closed_error is None)
        await guard.close()
        said.close()
        if signum is None:
            final = await settle(client, args.timeout)
            if not asked_to_move(args) or moved(pose(before), pose(final), guard.seen_moving):
                report(args, before, final, moved=True if asked_to_move(args) else None)
                return EXIT_OK
            facts = said.into(await gather(client, args.timeout))
            answer = unexplained(diagnose(facts, motion))
            report(args, before, final, moved=False, why=answer)
            print_answer(answer, sys.stderr, "rtmu drive: the robot did not move: ")
            return answer.exit_code
        # Interrupted: the stop is out; the last pose is worth a short wait, not a long one.
        after: dict[str, Any] | None = None
        with contextlib.suppress(TimeoutError, ClientError):
            async with asyncio.timeout(AFTER_INTERRUPT):
                after = await settle(client, min(args.timeout, AFTER_INTERRUPT))
        report(args, before, after, interrupted=signal_name(signum))
        raise Interrupted(signum, Said(N_("the robot was stopped")))

    try:
        check(args)
    except UsageError as exc:
        print(_("rtmu drive: {exc}").format(exc=exc), file=sys.stderr)
        return EXIT_USAGE
    return run_with_client("drive", args, body, role=Role.OPERATOR)


async def start_guardian(args: argparse.Namespace) -> GuardianHandle | None:
    """The guardian for this drive (``rtmu.guardian``); None, with one line on stderr, if it cannot log in."""
    from ..guardian.handle import GuardianUnavailable, start_ready
    from ..guardian.messages import Hello

    host, port = args.server
    try:
        target = Target(host, port, args.user, current_password(), protocol=args.protocol)
        return await start_ready(Hello(target, args.timeout), args.timeout)
    except GuardianUnavailable as exc:
        print(
            _(
                "rtmu drive: warning: guardian not available ({visible}); if this process is killed "
                "or frozen, only the server's 2 s watchdog stops the robot"
            ).format(visible=visible(exc)),
            file=sys.stderr,
            flush=True,
        )
        return None


async def refuse(args: argparse.Namespace, client: AriaClient, motion: Motion) -> int:
    """This login may not drive: say why (``rtmu why``'s answer) and exit with its code."""
    from ..client.why import diagnose
    from ..client.why_gather import gather
    from .why import print_answer

    answer = diagnose(await gather(client, args.timeout), motion)
    if args.json:
        print_json(
            {"before": None, "after": None, "seconds": args.seconds, "moved": False, "why": answer.as_json()}
        )
    print_answer(answer, sys.stderr, "rtmu drive: ")
    return answer.exit_code


def asked_to_move(args: argparse.Namespace) -> bool:
    return (args.trans != 0 or args.rot != 0) and args.throttle > 0


def pose(status: dict[str, Any]) -> tuple[float, float, float]:
    return (status["x"], status["y"], status["th"])


class StatusWords:
    """The server's status words while we drive (``updateStrings``, broadcast when they change), kept
    until :meth:`close` — our own stop afterwards would replace them with "Stopped"."""

    def __init__(self, client: AriaClient) -> None:
        self.client = client
        self.last: UpdateStrings | None = None
        self.open = client.supports("updateStrings")
        if self.open:
            client.request("updateStrings", -1, self._on_strings)

    def _on_strings(self, packet: Packet) -> None:
        from ..client.errors import ClientError
        from ..protocol.errors import ProtocolError
        from ..protocol.payloads.robot import UpdateStrings

        with contextlib.suppress(ClientError, ProtocolError):
            value = packet.decode()
            if self.open and isinstance(value, UpdateStrings):
                self.last = value

    def close(self) -> None:
        from ..client.errors import ClientError

        if self.open:
            self.open = False
            with contextlib.suppress(ClientError):
                self.client.stop_request("updateStrings")

    def into(self, facts: Facts) -> Facts:
        if self.last is None:
            return facts
        s = self.last
        return dataclasses.replace(facts, status=s.status, mode=s.mode, extended_status=s.extended_status)


def report(
    args: argparse.Namespace,
    before: dict[str, Any],
    after: dict[str, Any] | None,
    interrupted: str | None = None,
    moved: bool | None = None,
    why: Answer | None = None,
) -> None:
    """The poses on stdout; ``after`` None: the status did not come in time after an interrupt."""
    if args.json:
        obj: dict[str, Any] = {"before": before, "after": after, "seconds": args.seconds}
        if interrupted is not None:
            obj["interrupted"] = interrupted
        if moved is not None:
            obj["moved"] = moved
        if why is not None:
            obj["why"] = why.as_json()
        print_json(obj)
    elif after is not None:
        print(_("after:  {status_line}").format(status_line=status_line(after)), flush=True)
    else:
        print(_("after:  unknown (no status in time)"), flush=True)


async def drive(
    client: AriaClient,
    ratios: RatioDrive,
    seconds: float,
    held: Callable[[], bool] = lambda: False,
    guard: DriveGuard | None = None,
) -> None:
    """Resend ``ratios`` every :data:`RESEND` s for ``seconds``; nothing while ``held()`` (Ctrl-Z).

    With a ``guard``, a link fault raises :class:`LinkFault` the moment it is seen (the guard
    wakes this loop when status arrives or a ping fails, and at the instant status would go stale).
    """
    import asyncio

    from ..client.drive_guard import LinkFault

    clock = client.clock
    end = clock() + seconds
    next_send = clock()
    while True:
        now = clock()
        if now >= end:
            return
        if guard is not None and not held():
            why = await guard.judged_fault(now)
            if why is not None:
                raise LinkFault(why)
        if now >= next_send:
            if not held():
                client.send("ratioDrive", ratios)
            next_send = next_resend(next_send, now)
        if client.closed_error is not None:
            if guard is not None:
                raise LinkFault(f"lost the link: {client.closed_error}")
            raise client.closed_error
        wake = min(next_send, end)
        if guard is None:
            await asyncio.sleep(max(0.0, wake - clock()))
            continue
        guard.changed.clear()
        slept_at = clock()
        due = timer_due(min(wake, guard.next_check(now)), slept_at)
        with contextlib.suppress(TimeoutError):
            async with asyncio.timeout(due - slept_at):
                await guard.changed.wait()
        if not guard.changed.is_set():  # woke by its timer: how late this machine ran it
            guard.health.note_wake(clock() - due)


def next_resend(due: float, now: float) -> float:
    """When to resend after a ``ratioDrive`` that was due at ``due`` went out at ``now``: every
    :data:`RESEND` s — but a loop that fell behind (the machine did not run it) starts again from
    now rather than sending the missed ones back to back."""
    return due + RESEND if due + RESEND > now else now + RESEND


def timer_due(wake: float, now: float) -> float:
    """When a wait that begins at ``now`` for ``wake`` is due: never before it begins.

    Its lateness (``HealthMonitor.note_wake``) lowers the stale limit's ceiling, so it must be the
    machine's lateness in running this wait — a deadline already past when the wait began is not.
    Measured as that (a resend due 0.3 s ago after a stall counted as 0.3, 0.2, 0.1 s late), one
    stall of the process looked like several and pinned the limit to its floor; rtmu drive then
    stopped on "good" Wi-Fi ("learned jitter 280 ms, limit 0.25 s")."""
    return max(wake, now)


RECONNECT_FOR_STOP = 1.0
"""Seconds a new connection may take to log in and carry the stop after ours was lost."""


async def stop_on_a_new_connection(args: argparse.Namespace) -> bool:
    """Log in again at once and send zero ratios + ``stop``; True once they have left this process."""
    from ..client.connection import AriaClient
    from ..client.errors import ClientError
    from ..client.roles import Role

    host, port = args.server
    fresh = AriaClient()
    try:
        await fresh.connect(
            Target(host, port, args.user, current_password(), protocol=args.protocol),
            timeout=RECONNECT_FOR_STOP,
            role=Role.OPERATOR,  # it sends only zero ratios and stop
        )
        stop(fresh)
        return await fresh.flush(RECONNECT_FOR_STOP)
    except ClientError:
        return False
    finally:
        with contextlib.suppress(ClientError):
            await fresh.disconnect()


def stop(client: AriaClient) -> None:
    """Zero ratios and ``stop``; never raises (we are often in a ``finally``)."""
    from ..client.errors import ClientError
    from ..protocol.payloads.drive import RatioDrive

    with contextlib.suppress(ClientError):
        client.send("ratioDrive", RatioDrive(0.0, 0.0, 0.0))
    if client.supports("stop"):
        with contextlib.suppress(ClientError):
            client.send("stop")


async def settle(client: AriaClient, timeout: float) -> dict[str, Any]:
    """The status once the robot stands still (or after :data:`SETTLE` s)."""
    import asyncio

    loop = asyncio.get_running_loop()
    deadline = loop.time() + SETTLE
    while True:
        status = await fetch_status(client, timeout)
        if (status["vel"] == 0 and status["rot_vel"] == 0) or loop.time() >= deadline:
            return status
        await asyncio.sleep(0.1)

"""``rtmu bridge HOST[:PORT] --foxglove [--port 8765] [--allow-drive]``: the robot, live, in Foxglove.

Follows the robot as the window does and serves the recorder's decoded channels on a
Foxglove WebSocket server (127.0.0.1 unless ``--bind`` says otherwise). Only Foxglove's own
app origins (and ``--allow-origin``) and this machine's names (and ``--allow-host``) may
connect (:mod:`rtmu.recorder.foxglove_gate`). Nothing drives unless ``--allow-drive``: then
every client must open the URL printed at the start (it carries a fresh token), one client
drives at a time, and Twist-shaped JSON it publishes (Teleop panel, ``/cmd_vel``, publish
rate 5 Hz or more) drives through the session's drive lease with the window's stop rules,
and a guardian process stops the robot if this process dies; on an address other than
loopback it warns. Ends after ``--seconds`` or at Ctrl-C / SIGTERM / SIGHUP, stopping the
robot first.
"""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING, Any
from urllib.parse import quote

from ..base.exit_codes import EXIT_CONNECTION, EXIT_OK, EXIT_USAGE
from ..base.i18n import _
from ..base.notices import Notice
from ..base.textsafe import visible
from ..client.errors import ClientError
from ..client.roles import Role
from ..recorder.topics import BRIDGE_PORT as DEFAULT_PORT
from ..values.target import Target
from ._common import UsageError, add_connection_arguments, fail, positive_float, read_password, signal_name
from ._follow import EndingSignals, follow, until_connected
from ._options import add_fps_option

if TYPE_CHECKING:
    from ..client.runner import ClientRunner
    from ..recorder.bridge import Bridge

BEAT = 0.04
"""The main thread beats for the guardian as the window's UI thread does."""
APP = "https://app.foxglove.dev/?ds=foxglove-websocket&ds.url="
TOLD_REFUSALS = 20
"""Refused handshakes said one by one; after that every 100th (a port scan must not flood the terminal)."""


def register(subparsers: Any) -> None:
    from ..recorder.foxglove_gate import FOXGLOVE_ORIGINS

    p = subparsers.add_parser(
        "bridge",
        help=_("serve the robot live to Foxglove (WebSocket); --allow-drive lets its Teleop panel drive"),
        description=_(
            "Connect, follow the robot as the window does and publish pose, TF, status, sonar, "
            "laser, camera, map, link health, notices and stops on a Foxglove WebSocket server. Without "
            "--allow-drive nothing a Foxglove client sends can move the robot."
        ),
    )
    add_connection_arguments(p)
    p.add_argument("--foxglove", action="store_true", required=True, help=_("a Foxglove WebSocket server"))
    p.add_argument("--ws-port", dest="ws_port", type=int, default=DEFAULT_PORT, metavar="PORT",
                   help=f"its port (default {DEFAULT_PORT}; 0: any free one, printed)")  # fmt: skip
    p.add_argument("--port", dest="ws_port", type=int, help=argparse.SUPPRESS)  # its old name
    p.add_argument(
        "--bind",
        default="127.0.0.1",
        metavar="ADDR",
        help=_("its address (default 127.0.0.1: this machine only; 0.0.0.0 lets the network in)"),
    )
    p.add_argument(
        "--allow-drive",
        action="store_true",
        help=_(
            "let Twist messages from Foxglove clients (/cmd_vel, at 5 Hz or more) drive the robot, one "
            "client at a time; every client must then open the URL printed at the start (it holds a token)"
        ),
    )
    p.add_argument(
        "--allow-origin",
        action="append",
        default=[],
        metavar="ORIGIN",
        help="also let browser pages from ORIGIN connect (repeatable; default: Foxglove's own only, "
        + ", ".join(sorted(FOXGLOVE_ORIGINS))
        + ")",
    )
    p.add_argument(
        "--allow-host",
        action="append",
        default=[],
        metavar="NAME",
        help=_(
            "also accept requests for host NAME (repeatable; default: IP addresses, localhost and this "
            "machine's names only)"
        ),
    )
    p.add_argument("--throttle", type=positive_float, default=50.0, metavar="PCT",
                   help=_("throttle of bridge drives, %% (default 50)"))  # fmt: skip
    add_fps_option(p, default=0.0, none_means="no pictures")
    p.add_argument(
        "--seconds", type=positive_float, default=None, metavar="S", help=_("stop after S seconds")
    )
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..client.runner import ClientRunner
    from ..client.session import SessionConfig
    from ..recorder.bridge import LEASE_TTL, Bridge, DriveLimits
    from ..recorder.foxglove_gate import Gate

    if not 0 <= args.ws_port <= 65535:
        return fail("bridge", f"--ws-port {args.ws_port} is not 0…65535", EXIT_USAGE)
    if args.throttle > 100:
        return fail("bridge", "--throttle is at most 100", EXIT_USAGE)
    try:
        password = read_password(args)
    except UsageError as exc:
        return fail("bridge", str(exc), EXIT_USAGE)
    except (KeyboardInterrupt, EOFError):
        return fail("bridge", "cancelled", EXIT_USAGE)

    def tell(notice: Notice) -> None:
        print(_("rtmu bridge: {visible}").format(visible=visible(notice.text)), file=sys.stderr)

    role = Role.OPERATOR if args.allow_drive else Role.OBSERVER  # read-only: it cannot command at all
    config = SessionConfig(connect_timeout=args.timeout, guardian=args.allow_drive, role=role)
    runner = ClientRunner(config=config, lease_ttl=LEASE_TTL)
    runner.on_notice = tell
    bridge = Bridge(
        host=args.bind,
        port=args.ws_port,
        lease=runner.lease if args.allow_drive else None,
        limits=DriveLimits(throttle=args.throttle),
        gate=Gate.make(allow_origins=args.allow_origin, allow_hosts=args.allow_host),
    )
    bridge.server.on_refused = _refusals_told()
    warn_exposure(args.bind, args.allow_drive)
    runner.on_publish = bridge.published
    runner.on_notice_sent = bridge.notice

    def stopped(reason: str, sent: bool) -> None:
        bridge.stopped(reason, sent)
        if reason.startswith("lease link"):  # a stream that paused is the operator's "release": not said
            print(
                _("rtmu bridge: stopped the robot: {visible}").format(
                    visible=visible(reason.removeprefix("lease link: "))
                ),
                file=sys.stderr,
            )

    runner.on_stop = stopped
    with EndingSignals() as ending:
        try:
            bridge.start()
        except Exception as exc:
            return fail("bridge", f"cannot serve on {args.bind}:{args.ws_port}: {exc}", EXIT_CONNECTION)
        code = serve(args, runner, bridge, ending, password)
    if ending.exit_code is not None and code == EXIT_OK:
        return fail("bridge", f"ended by {signal_name(ending.signum or 0)}", ending.exit_code)
    return code


def serve(
    args: argparse.Namespace, runner: ClientRunner, bridge: Bridge, ending: EndingSignals, password: str
) -> int:
    """Connect and follow until ``--seconds`` or a signal; the bridge and the runner end either way."""
    host, port = args.server
    runner.start()
    try:
        future = runner.connect(Target(host, port, args.user, password, protocol=args.protocol))
        try:
            if not until_connected(future, ending.event, args.timeout + 1.0):
                return EXIT_OK  # a signal came first: its code is the command's
        except ClientError as exc:
            return fail("bridge", str(exc), exc.exit_code)
        except Exception as exc:
            return fail("bridge", f"could not connect: {exc}", EXIT_CONNECTION)
        announce(bridge)
        follow(runner, ending.event, seconds=args.seconds, camera_hz=args.fps, beat=BEAT)
    finally:
        bridge.close()  # ends any bridge drive first
        runner.close()  # stops the robot only if a bridge drive moved it (client.roles)
    return EXIT_OK


def announce(bridge: Bridge) -> None:
    """The URL to open, printed once (with a drive bridge's token: it is shown nowhere else)."""
    if bridge.drive is None:
        print(_("rtmu bridge: {url} (no drive)").format(url=bridge.url), file=sys.stderr, flush=True)
        return
    print(
        _(
            "rtmu bridge: {url} (drive allowed from /cmd_vel, one client at a time; the URL holds "
            "this run's token: share it only with who may drive)"
        ).format(url=bridge.url),
        file=sys.stderr,
    )
    app = APP + quote(bridge.url, safe="")
    print(_("rtmu bridge: in Foxglove's web app: {app}").format(app=app), file=sys.stderr, flush=True)


def warn_exposure(bind: str, allow_drive: bool) -> None:
    """A bridge the network can reach says so; one that also drives warns."""
    from ..recorder.foxglove_gate import loopback_only

    if loopback_only(bind):
        return
    if allow_drive:
        print(
            _(
                "rtmu bridge: WARNING: --allow-drive on {visible}, an address other hosts can reach: "
                "anyone with the printed URL (its token) on the network can drive the robot. Bind "
                "127.0.0.1 and tunnel (ssh -L) unless the network is yours alone."
            ).format(visible=visible(bind)),
            file=sys.stderr,
            flush=True,
        )
    else:
        print(
            _(
                "rtmu bridge: serving on {visible}: other hosts on the network can watch the robot "
                "(they cannot drive it)"
            ).format(visible=visible(bind)),
            file=sys.stderr,
            flush=True,
        )


def _refusals_told() -> Any:
    count = 0

    def told(reason: str) -> None:
        nonlocal count
        count += 1
        if count <= TOLD_REFUSALS or count % 100 == 0:
            text = f"rtmu bridge: refused a connection ({count}): {visible(reason)}"
            print(text, file=sys.stderr, flush=True)

    return told

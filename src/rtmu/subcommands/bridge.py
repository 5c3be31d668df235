"""``rtmu bridge HOST[:PORT] --foxglove [--port 8765] [--allow-drive]``: the robot, live, in Foxglove.

Follows the robot as the window does and serves the recorder's decoded channels on a
Foxglove WebSocket server (127.0.0.1 unless ``--bind`` says otherwise). Nothing drives
unless ``--allow-drive``: then Twist-shaped JSON that a Foxglove client publishes
(Teleop panel, ``/cmd_vel``, publish rate 5 Hz or more) drives through the session's
drive lease with the window's stop rules, and a guardian process stops the robot if
this process dies. Ends after ``--seconds`` or at Ctrl-C / SIGTERM / SIGHUP, stopping the
robot first.
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from typing import Any

from ..client.errors import ClientError
from ..client.runner import ClientRunner
from ..client.session import SessionConfig
from ..exit_codes import EXIT_CONNECTION, EXIT_OK, EXIT_USAGE
from ..notices import Notice
from ..recorder.bridge import DEFAULT_PORT, LEASE_TTL, Bridge, DriveLimits
from ..textsafe import visible
from ._common import UsageError, add_connection_arguments, fail, positive_float, read_password
from ._follow import follow

BEAT = 0.04
"""The main thread beats for the guardian as the window's UI thread does."""


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "bridge",
        help="serve the robot live to Foxglove (WebSocket); --allow-drive lets its Teleop panel drive",
        description="Connect, follow the robot as the window does and publish pose, TF, status, sonar, "
        "laser, camera, map, link health, notices and stops on a Foxglove WebSocket server. Without "
        "--allow-drive nothing a Foxglove client sends can move the robot.",
    )
    add_connection_arguments(p)
    p.add_argument("--foxglove", action="store_true", required=True, help="a Foxglove WebSocket server")
    p.add_argument("--port", dest="ws_port", type=int, default=DEFAULT_PORT, metavar="PORT",
                   help=f"its port (default {DEFAULT_PORT}; 0: any free one, printed)")  # fmt: skip
    p.add_argument("--bind", default="127.0.0.1", metavar="ADDR", help="its address (default 127.0.0.1)")
    p.add_argument(
        "--allow-drive",
        action="store_true",
        help="let Twist messages from Foxglove clients (/cmd_vel, at 5 Hz or more) drive the robot",
    )
    p.add_argument("--throttle", type=positive_float, default=50.0, metavar="PCT",
                   help="throttle of bridge drives, %% (default 50)")  # fmt: skip
    p.add_argument("--camera-hz", type=float, default=0.0, metavar="HZ", help="ask for camera pictures")
    p.add_argument("--seconds", type=positive_float, default=None, metavar="S", help="stop after S seconds")
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    if not 0 <= args.ws_port <= 65535:
        return fail("bridge", f"--port {args.ws_port} is not 0…65535", EXIT_USAGE)
    if args.throttle > 100:
        return fail("bridge", "--throttle is at most 100", EXIT_USAGE)
    try:
        password = read_password(args)
    except UsageError as exc:
        return fail("bridge", str(exc), EXIT_USAGE)
    except (KeyboardInterrupt, EOFError):
        return fail("bridge", "cancelled", EXIT_USAGE)
    host, port = args.server

    def tell(notice: Notice) -> None:
        print(f"rtmu bridge: {visible(notice.text)}", file=sys.stderr)

    config = SessionConfig(connect_timeout=args.timeout, guardian=args.allow_drive)
    runner = ClientRunner(config=config, lease_ttl=LEASE_TTL)
    runner.on_notice = tell
    bridge = Bridge(
        host=args.bind,
        port=args.ws_port,
        lease=runner.lease if args.allow_drive else None,
        limits=DriveLimits(throttle=args.throttle),
    )
    runner.on_publish = bridge.published
    runner.on_notice_sent = bridge.notice

    def stopped(reason: str, sent: bool) -> None:
        bridge.stopped(reason, sent)
        if reason.startswith("lease link"):  # a stream that paused is the operator's "release": not said
            print(
                f"rtmu bridge: stopped the robot: {visible(reason.removeprefix('lease link: '))}",
                file=sys.stderr,
            )

    runner.on_stop = stopped
    ended = threading.Event()
    ending = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
    previous = {s: signal.signal(s, lambda *_: ended.set()) for s in ending}
    try:
        bridge.start()
    except Exception as exc:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        return fail("bridge", f"cannot serve on {args.bind}:{args.ws_port}: {exc}", EXIT_USAGE)
    runner.start()
    try:
        future = runner.connect(host, port, args.user, password, protocol=args.protocol)
        try:
            future.result(args.timeout + 1.0)
        except ClientError as exc:
            return fail("bridge", str(exc), exc.exit_code)
        except Exception as exc:
            return fail("bridge", f"could not connect: {exc}", EXIT_CONNECTION)
        drive = "drive allowed from /cmd_vel" if args.allow_drive else "no drive"
        print(f"rtmu bridge: ws://{args.bind}:{bridge.port} ({drive})", file=sys.stderr, flush=True)
        follow(runner, ended, seconds=args.seconds, camera_hz=args.camera_hz, beat=BEAT)
    finally:
        bridge.close()  # ends any bridge drive first
        runner.stop_and_wait(0.5)
        runner.close()
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    return EXIT_OK

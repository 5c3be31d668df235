"""``rtmu record HOST[:PORT] --out FILE.mcap [--seconds S]``: a flight recording without the window.

The same session and the same recorder as the window's: the raw bytes both ways, the
robot's pose, status, sonar, map, camera pictures (``--camera-hz``), link health,
notices and stops. Ends after ``--seconds``, or at Ctrl-C / SIGTERM / SIGHUP, finishing the file; a
lost link is reconnected and recorded on in the same file.
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_CONNECTION, EXIT_OK, EXIT_USAGE
from ..base.textsafe import visible
from ._common import UsageError, add_connection_arguments, fail, positive_float, read_password

if TYPE_CHECKING:
    from ..base.notices import Notice
    from ..values.state import StateChange


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "record",
        help="record a session to an MCAP file (raw bytes + decoded channels), headless",
        description="Connect, follow the robot as the window does and write everything to FILE.mcap: "
        "the exact bytes both ways (rtmu decode FILE.mcap explains them), pose, status, sonar, map, "
        "camera, link health, notices and stops, readable in Foxglove.",
    )
    add_connection_arguments(p)
    p.add_argument("--out", type=Path, required=True, metavar="FILE.mcap", help="the recording to write")
    p.add_argument("--seconds", type=positive_float, default=None, metavar="S", help="stop after S seconds")
    p.add_argument(
        "--camera-hz",
        type=float,
        default=0.0,
        metavar="HZ",
        help="also ask for camera pictures this often (default 0: none)",
    )
    p.add_argument(
        "--max-mb", type=positive_float, default=1024.0, metavar="MB", help="size limit of the file (1024)"
    )
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..client.errors import ClientError
    from ..client.runner import ClientRunner
    from ..client.session import SessionConfig
    from ..recorder.recorder import Recorder, RecorderConfig
    from ..values.state import ConnectionChanged, Phase
    from ._follow import follow

    out: Path = args.out
    if out.is_dir():
        return fail("record", f"{out} is a directory", EXIT_USAGE)
    try:
        password = read_password(args)
    except UsageError as exc:
        return fail("record", str(exc), EXIT_USAGE)
    except (KeyboardInterrupt, EOFError):
        return fail("record", "cancelled", EXIT_USAGE)
    out.unlink(missing_ok=True)  # the operator named it: a new recording replaces an old one
    host, port = args.server

    def tell(notice: Notice) -> None:
        print(f"rtmu record: {visible(notice.text)}", file=sys.stderr)

    config = RecorderConfig(out.parent, path=out, max_bytes=int(args.max_mb * 1e6), keep_days=0)
    recorder = Recorder(config, tell)
    runner = ClientRunner(config=SessionConfig(connect_timeout=args.timeout), opener=recorder.opener())
    recorder.attach(runner)
    runner.on_notice = tell
    phases: list[Phase] = []
    connected = threading.Event()

    def published(change: StateChange) -> None:
        recorder.published(change)
        if isinstance(change, ConnectionChanged):
            phases.append(change.value.phase)
            if change.value.phase is Phase.CONNECTED:
                connected.set()

    runner.on_publish = published
    ended = threading.Event()
    ending = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
    previous = {s: signal.signal(s, lambda *_: ended.set()) for s in ending}
    runner.start()
    try:
        future = runner.connect(host, port, args.user, password, protocol=args.protocol)
        try:
            future.result(args.timeout + 1.0)
        except ClientError as exc:
            return fail("record", str(exc), exc.exit_code)
        except Exception as exc:
            return fail("record", f"could not connect: {exc}", EXIT_CONNECTION)
        print(f"rtmu record: recording {host}:{port} to {visible(str(out))}", file=sys.stderr)
        follow(runner, ended, seconds=args.seconds, camera_hz=args.camera_hz)
    finally:
        runner.close()
        recorder.close()
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    for recording in recorder.recordings:
        size = recording.path.stat().st_size if recording.path.exists() else 0
        print(
            f"rtmu record: {visible(str(recording.path))}: {size / 1e6:.2f} MB, "
            f"{recording.written_items} items, {recording.dropped} dropped",
            file=sys.stderr,
        )
    return EXIT_OK

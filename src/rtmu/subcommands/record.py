"""``rtmu record HOST[:PORT] --out FILE.mcap [--seconds S]``: a flight recording without the window.

The same session and the same recorder as the window's: the raw bytes both ways, the
robot's pose, status, sonar, map, camera pictures (``--fps``), link health,
notices and stops. Ends after ``--seconds``, or at Ctrl-C / SIGTERM / SIGHUP (exit 128 + N),
finishing the file; a lost link is reconnected and recorded on in the same file. It is an
observer: it never sends anything that moves or stops the robot.

Nothing is lost: the file is written as ``FILE.mcap.partial`` beside FILE and renamed to it at the
end, once the session logged in; an existing FILE is replaced only with ``--force`` (else refused
before connecting). A recording that never connected is deleted and leaves FILE as it was.
"""

from __future__ import annotations

import argparse
import sys
import threading
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_CONNECTION, EXIT_OK, EXIT_SIZE_LIMIT, EXIT_USAGE, NETWORK
from ..base.i18n import _
from ..base.notices import Kind, Notice
from ..base.textsafe import visible
from ..base.units import file_size
from ..client.errors import ClientError
from ..client.roles import Role
from ..values.state import ConnectionChanged, Phase, StateChange
from ..values.target import Target
from ._common import UsageError, add_connection_arguments, fail, positive_float, read_password, signal_name
from ._follow import EndingSignals, follow, until_connected
from ._options import add_fps_option
from ._output import add_force_option, check_file, partial_path, settle

if TYPE_CHECKING:
    from ..client.runner import ClientRunner
    from ..recorder import Recorder

EXITS = (*NETWORK, EXIT_SIZE_LIMIT)


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "record",
        help=_("record a session to an MCAP file (raw bytes + decoded channels), headless"),
        description=_(
            "Connect, follow the robot as the window does and write everything to FILE.mcap: "
            "the exact bytes both ways (rtmu decode FILE.mcap explains them; the login's password digest is "
            "recorded as zeros), pose, status, sonar, map, camera, link health, notices and stops, readable "
            "in Foxglove. It never moves or stops the robot. The file is written as FILE.mcap.partial and "
            "renamed at the end."
        ),
    )
    add_connection_arguments(p)
    p.add_argument("--out", type=Path, required=True, metavar="FILE.mcap", help=_("the recording to write"))
    add_force_option(p, "an existing FILE.mcap")
    p.add_argument(
        "--seconds", type=positive_float, default=None, metavar="S", help=_("stop after S seconds")
    )
    add_fps_option(p, default=0.0, none_means="no pictures")
    p.add_argument(
        "--max-mb",
        type=positive_float,
        default=1024.0,
        metavar="MB",
        help=f"size limit of the file (default 1024): reached, the recording ends, exit {EXIT_SIZE_LIMIT}",
    )
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..client.runner import ClientRunner
    from ..client.session import SessionConfig
    from ..recorder import Recorder, RecorderConfig

    out: Path = args.out
    try:
        check_file(out, force=args.force)  # before connecting: an existing recording is never touched
        partial = partial_path(out)
        password = read_password(args)
    except UsageError as exc:
        return fail("record", str(exc), EXIT_USAGE)
    except (KeyboardInterrupt, EOFError):
        return fail("record", "cancelled", EXIT_USAGE)
    stopped: list[str] = []

    with EndingSignals() as ending:

        def tell(notice: Notice) -> None:
            if notice.kind is not Kind.RECORDING:
                print(_("rtmu record: {visible}").format(visible=visible(notice.text)), file=sys.stderr)
            elif not stopped:  # its size limit, a full disk: said once, and the recording ends
                why = next((r.stopped for r in recorder.recordings if r.stopped), None) or notice.text
                stopped.append(why)
                print(
                    _("rtmu record: {visible}; the recording ends here").format(visible=visible(why)),
                    file=sys.stderr,
                )
                ending.event.set()

        config = RecorderConfig(out.parent, path=partial, max_bytes=int(args.max_mb * 1e6), keep_days=0)
        recorder = Recorder(config, tell)
        session_config = SessionConfig(connect_timeout=args.timeout, role=Role.OBSERVER)  # never commands
        runner = ClientRunner(config=session_config, opener=recorder.opener())
        recorder.attach(runner)
        runner.on_notice = tell
        connected = threading.Event()

        def published(change: StateChange) -> None:
            recorder.published(change)
            if isinstance(change, ConnectionChanged) and change.value.phase is Phase.CONNECTED:
                connected.set()

        runner.on_publish = published
        try:
            code = _record(args, runner, ending, password, partial)
        finally:
            runner.close()
            recorder.close()
    kept = _keep(recorder, out, force=args.force, logged_in=connected.is_set())
    if code != EXIT_OK:
        return code
    if stopped:
        return EXIT_SIZE_LIMIT
    if ending.exit_code is not None:
        return fail("record", f"ended by {signal_name(ending.signum or 0)}", ending.exit_code)
    return EXIT_OK if kept else EXIT_CONNECTION


def _record(
    args: argparse.Namespace, runner: ClientRunner, ending: EndingSignals, password: str, partial: Path
) -> int:
    host, port = args.server
    runner.start()
    future = runner.connect(Target(host, port, args.user, password, protocol=args.protocol))
    try:
        if not until_connected(future, ending.event, args.timeout + 1.0):
            return EXIT_OK  # a signal came first: its code is the command's
    except ClientError as exc:
        return fail("record", str(exc), exc.exit_code)
    except Exception as exc:
        return fail("record", f"could not connect: {exc}", EXIT_CONNECTION)
    shown = f"{visible(str(args.out))} (as {visible(partial.name)} until it ends)"
    print(
        _("rtmu record: recording {host}:{port} to {shown}").format(host=host, port=port, shown=shown),
        file=sys.stderr,
    )
    follow(runner, ending.event, seconds=args.seconds, camera_hz=args.fps)
    return EXIT_OK


def _keep(recorder: Recorder, out: Path, *, force: bool, logged_in: bool) -> bool:
    """Rename the finished recording to ``out`` (True), or delete it if it never logged in (False)."""
    kept = False
    for recording in recorder.recordings:
        path = recording.path
        if not path.exists():
            continue
        if not logged_in:
            path.unlink(missing_ok=True)  # nothing of the robot in it: the operator's old file stays
            continue
        final = settle(path, out, force=force) if not kept else path
        kept = True
        size = final.stat().st_size
        if final != out:
            print(
                _("rtmu record: {visible} appeared meanwhile and was kept").format(visible=visible(str(out))),
                file=sys.stderr,
            )
        print(
            _("rtmu record: {visible}: {size}, {written_items} items, {dropped} dropped").format(
                visible=visible(str(final)),
                size=file_size(size),
                written_items=recording.written_items,
                dropped=recording.dropped,
            ),
            file=sys.stderr,
        )
    return kept

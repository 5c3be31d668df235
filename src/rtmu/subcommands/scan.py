"""``rtmu scan HOST[:PORT] start NAME | status | loop start|end [TAG] | stop [--download DIR]``: map scans.

What it does, in the help's plain words: :data:`DESCRIPTION`. A scan logs; the operator drives, so
this is an observer (its client cannot send a motion request).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..base.exit_codes import EXIT_OK, EXIT_REFUSED, EXIT_TIMEOUT, EXIT_USAGE, NETWORK
from ..base.i18n import N_, _, error_words
from ..base.textsafe import visible
from ..client.errors import NotSupported
from ..client.roles import Role
from ._actions import action_parser, end_progress, progress_printer
from ._common import add_connection_arguments, fail, print_json, run_with_client

if TYPE_CHECKING:
    from ..client.connection import AriaClient

EXITS = (*NETWORK, EXIT_REFUSED)
DESCRIPTION = N_(
    "Scan for a map. The robot logs its laser and its path into NAME.2d (lower case) in its files folder "
    "while it is driven round the site (rtmu drive, the window); Mapper3 or MobilePlanner turn the log "
    "into a map. Loop tags mark where a loop starts and ends. stop --download DIR ends the scan and "
    "fetches the log into DIR (an existing file there is refused without --force, before the scan is "
    "ended). A loop tag the robot does not confirm in time is a timeout; what the robot refuses (a scan "
    "already runs, none runs, its file could not be opened) is a refusal in its own words."
)


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "scan",
        help=_("scan for a map: start, status, loop tags, stop and download the .2d (mappingStart …)"),
        description=_(DESCRIPTION),
    )
    add_connection_arguments(p)
    actions = p.add_subparsers(dest="action", metavar="start|status|loop|stop", required=True)
    start = action_parser(
        actions, "start", "start a scan", "Start a scan named NAME (the robot writes NAME.2d)."
    )
    start.add_argument("name", metavar="NAME", help=_("the scan's name"))
    action_parser(actions, "status", "is a scan running?", "Say whether a scan runs, and which.")
    loop = action_parser(
        actions, "loop", "tag a loop", "Mark where a loop starts or ends in the running scan."
    )
    loop.add_argument("edge", choices=("start", "end"), help=_("start or end of the loop"))
    loop.add_argument("tag", nargs="?", default="1", metavar="TAG", help=_("the loop's tag (default 1)"))
    stop = action_parser(actions, "stop", "end the scan", "End the scan, and fetch its .2d with --download.")
    stop.add_argument("--download", type=Path, metavar="DIR", help=_("fetch the scan into this folder"))
    stop.add_argument("--force", action="store_true", help=_("replace the file in DIR if it exists"))
    p.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    from ..client.download import LocalFileError

    try:
        body = {"start": _start, "status": _status, "loop": _loop, "stop": _stop}[args.action](args)
    except (ValueError, LocalFileError) as exc:
        return fail("scan", error_words(exc), EXIT_USAGE)
    return run_with_client("scan", args, body, role=Role.OBSERVER)  # a scan logs; the operator drives


def _start(args: argparse.Namespace) -> Any:
    from ..client.scan import scan_name, start_scan

    name = scan_name(args.name)

    async def body(client: AriaClient) -> int:
        file_name = await start_scan(client, name, timeout=args.timeout)
        if args.json:
            print_json({"scanning": True, "file": file_name})
        else:
            print(
                _("scanning: the robot writes {visible}; drive it round the site, then 'stop'").format(
                    visible=visible(file_name)
                )
            )
        return EXIT_OK

    return body


def _status(args: argparse.Namespace) -> Any:
    from ..client.scan import scan_status

    async def body(client: AriaClient) -> int:
        status = await scan_status(client, timeout=args.timeout)
        if args.json:
            print_json({"scanning": status.scanning, "name": status.name, "file": status.file_name})
        elif status.scanning:
            print(
                _("scanning {visible} (file {visible2})").format(
                    visible=visible(status.name), visible2=visible(status.file_name)
                )
            )
        else:
            print(_("not scanning"))
        return EXIT_OK

    return body


def _loop(args: argparse.Namespace) -> Any:
    from ..client.remote_files import Refused
    from ..client.scan import scan_status, scan_unavailable, tag_loop

    async def body(client: AriaClient) -> int:
        unavailable = scan_unavailable(client)
        if "scan_loops" in unavailable:  # say what the robot lacks before asking whether it scans
            raise NotSupported("mappingLoopStart", unavailable["scan_loops"])
        if (
            "scan_status" not in unavailable
            and not (await scan_status(client, timeout=args.timeout)).scanning
        ):
            raise Refused("no scan is running on the robot; it ignores loop tags then")
        taken = await tag_loop(client, start=args.edge == "start", tag=args.tag, timeout=args.timeout)
        if args.json:
            print_json({"loop": args.edge, "tag": args.tag, "taken": taken})
        if not taken:
            return fail(
                "scan", f"the robot did not confirm the loop tag within {args.timeout:g} s", EXIT_TIMEOUT
            )
        if not args.json:
            print(_("loop {edge} tagged {visible!r}").format(edge=args.edge, visible=visible(args.tag)))
        return EXIT_OK

    return body


def _stop(args: argparse.Namespace) -> Any:
    from ..client.download import check_destination, download_file
    from ..client.remote_files import Refused, local_name
    from ..client.scan import scan_status, stop_scan

    folder: Path | None = args.download
    if folder is not None and not folder.is_dir():
        raise ValueError(f"no folder {folder} to download the scan into")

    async def body(client: AriaClient) -> int:
        local: Path | None = None
        if folder is not None:
            status = await scan_status(client, timeout=args.timeout)
            if not status.scanning:
                raise Refused("no scan is running on the robot")
            local = check_destination(folder / local_name(status.file_name), overwrite=args.force)
        file_name = await stop_scan(client, timeout=args.timeout)
        out: dict[str, Any] = {"stopped": True, "file": file_name}
        if local is not None:
            printer = progress_printer(f"getting {visible(file_name)}")
            try:
                done = await download_file(
                    client, file_name, local, overwrite=args.force, progress=printer, timeout=args.timeout
                )
            finally:
                end_progress(printer)
            out |= {"downloaded": str(local), "bytes": done.size}
        if args.json:
            print_json(out)
        else:
            print(
                _("scan ended: {value}").format(
                    value=visible(file_name) or "(the robot did not name its file)"
                )
            )
            if local is not None:
                print(_("downloaded to {local} ({value} bytes)").format(local=local, value=out["bytes"]))
        sys.stdout.flush()
        return EXIT_OK

    return body
